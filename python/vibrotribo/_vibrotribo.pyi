"""Type stubs of the extension module vibrotribo._vibrotribo (the Rust bindings). The
public API is the package `vibrotribo`, which wraps these into result objects."""

import os
from typing import Any, Dict, List, Mapping, Optional, Tuple, Union

__version__: str

class OrbitNotFound(RuntimeError):
    """No periodic orbit was found (Newton's method did not converge, the motion is not
    periodic, or the orbit is not differentiable)."""

class Config:
    """A configuration: the paper's default case, a TOML file (str or path), or a dict
    shaped like one, with keys overridden by keyword arguments (`__` for `.`:
    `excitation__omega_ratio=0.6`, or `**{"oscillator.gaps[1]": 0.03}`; derived keys such
    as `mass_ratio` as they are). SI units. Unknown keys raise KeyError, bad values
    ValueError, a missing file FileNotFoundError; messages name the key or file."""

    def __init__(
        self,
        source: Union["Config", Mapping[str, Any], str, "os.PathLike[str]", None] = None,
        /,
        **overrides: Any,
    ) -> None: ...
    @staticmethod
    def from_toml(text: str) -> "Config":
        """A configuration from TOML text."""
    def replace(self, **overrides: Any) -> "Config":
        """A copy with the overrides applied."""
    def to_dict(self) -> Dict[str, Any]:
        """The settings as a dict shaped like the TOML file (`Config(c.to_dict()) == c`)."""
    def to_toml(self) -> str:
        """The settings as TOML text."""
    @staticmethod
    def keys() -> List[str]:
        """Every key: the TOML file's (`section.name`), then the derived ones."""
    @property
    def masses(self) -> List[float]:
        """Masses m_i, kg."""
    @property
    def gaps(self) -> List[float]:
        """Gaps δ_k at rest, m."""
    @property
    def period_s(self) -> float:
        """Excitation period T, s."""
    @property
    def omega_ratio(self) -> float:
        """Ω = ω/√(k1/m1)."""
    @property
    def periods(self) -> int:
        """`run.periods`."""
    @property
    def transient_periods(self) -> int:
        """`run.transient_periods` (or its default)."""
    def __eq__(self, other: object) -> bool: ...

def simulate(config: Any, *, mechanics_only: bool = False, samples: bool = True) -> Dict[str, Any]:
    """One run: arrays t, x, v, y, d (and q, i, v_load, c, voc, vs), events, summary, error."""

def sweep(
    config: Any,
    param: str,
    values: List[float],
    *,
    continuation: str = "none",
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = 1e-4,
    settle: str = "auto",
    settle_cap: int = 2000,
) -> Dict[str, Any]:
    """A sweep: the columns of summary.csv, orbit.csv, impacts.csv and the settings."""

def map(
    config: Any,
    x: str,
    x_values: List[float],
    y: str,
    y_values: List[float],
    *,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = 1e-4,
    settle: str = "auto",
    settle_cap: int = 2000,
) -> Dict[str, Any]:
    """A map: the columns of map.csv and the settings."""

def load_sweep(
    config: Any,
    *,
    resistances: Optional[List[float]] = None,
    low: float = 1e3,
    high: float = 1e13,
    steps: int = 41,
    vq_points: Optional[int] = 400,
) -> Dict[str, Any]:
    """A load sweep: the columns of load_sweep.csv and vq_cycle.csv, the optimum."""

def periodic(
    config: Any,
    *,
    period: Optional[int] = None,
    transient: int = 100,
    guess: Optional[Tuple[List[float], List[float]]] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
) -> Dict[str, Any]:
    """A periodic orbit and its Floquet multipliers."""

def lyapunov(
    config: Any,
    *,
    periods: int = 1000,
    transient: int = 300,
    seed: int = 1,
    batches: int = 10,
) -> Dict[str, Any]:
    """The Lyapunov spectrum of a run."""

def continue_(
    config: Any,
    param: str,
    start: float,
    stop: float,
    *,
    period: Optional[int] = None,
    transient: int = 100,
    guess: Optional[Tuple[List[float], List[float]]] = None,
    max_points: Optional[int] = None,
    doubling_depth: Optional[int] = None,
    initial_step: Optional[float] = None,
    max_step: Optional[float] = None,
) -> Dict[str, Any]:
    """A continuation: the parameter's name and the branches."""

def grid(start: float, stop: float, steps: int) -> List[float]:
    """`steps` values equally spaced from `start` to `stop` (both included, `stop` exactly)."""

def log_spaced(start: float, stop: float, steps: int) -> List[float]:
    """`steps` values evenly spaced in the logarithm from `start` to `stop`."""
