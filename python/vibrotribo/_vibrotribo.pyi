"""Type stubs of the extension module vibrotribo._vibrotribo (the Rust bindings). The
public API is the package `vibrotribo`, which wraps these into result objects."""

import os
from typing import Any, Dict, Iterator, List, Literal, Mapping, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

SettleMode = Literal["auto", "fixed"]
ContinuationMode = Literal["none", "up", "down"]
ChirpSweep = Literal["linear", "logarithmic"]

DEFAULT_PERIOD_TOLERANCE: float
DEFAULT_SETTLE_CAP: int
MAX_GRID_POINTS: float
MAX_MEMORY_BYTES: float

__version__: str

class OrbitNotFound(RuntimeError):
    """No periodic orbit was found (Newton's method did not converge, the motion is not
    periodic, or the orbit is not differentiable)."""

class Config:
    """A configuration: the paper's default case, a TOML file (str or path), or a dict
    shaped like one, with keys overridden by keyword arguments (`__` for `.`:
    `excitation__omega_ratio=0.6`, or `**{"oscillator.gaps[1]": 0.03}`; derived keys such
    as `mass_ratio` as they are). SI units. Unknown keys raise KeyError (with the closest
    keys), bad values ValueError, a missing file FileNotFoundError; messages name the key or
    file. A random excitation costlier to build than 10⁹ harmonic evaluations is refused
    with its size unless `allow_large=True` (the command line's `--allow-large`); the
    configurations derived from this one keep the setting. Ctrl-C stops a build with
    KeyboardInterrupt."""

    def __init__(
        self,
        source: Union["Config", Mapping[str, Any], str, "os.PathLike[str]", None] = None,
        /,
        *,
        allow_large: bool = False,
        **overrides: Any,
    ) -> None: ...
    @staticmethod
    def from_toml(text: str, *, allow_large: bool = False) -> "Config":
        """A configuration from TOML text."""
    @property
    def allow_large(self) -> bool:
        """Whether the base motion may be built past the limit of 10⁹ harmonic evaluations."""
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
    def with_(self, **changes: Any) -> "Config":
        """A copy with the changes applied (the same as `replace`)."""
    def without(self, *keys: str) -> "Config":
        """A copy with `keys` back at their defaults."""
    def settings(self) -> Dict[str, Any]:
        """The settings as given (what was read and overridden)."""
    def __getitem__(self, key: str) -> Any:
        """The effective value of `key` (`section.name`, `name[i]`, a derived key)."""
    def get(self, key: str, default: Any = None) -> Any: ...
    def __contains__(self, key: object) -> bool: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def __hash__(self) -> int: ...
    def __eq__(self, other: object) -> bool: ...

def simulate(
    config: Any,
    *,
    mechanics_only: bool = False,
    samples: bool = True,
    settle: SettleMode = "fixed",
    settle_cap: int = 2000,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """One run: arrays t, x, v, y, d (and q, i, v_load, c, voc, vs), events, summary, error."""

def sweep(
    config: Any,
    param: str,
    values: List[float],
    *,
    continuation: ContinuationMode = "none",
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = 1e-4,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    floquet: bool = False,
    lyapunov: bool = False,
    allow_large: bool = False,
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
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    floquet: bool = False,
    allow_large: bool = False,
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
    allow_large: bool = ...,
) -> Dict[str, Any]:
    """A load sweep: the columns of load_sweep.csv and vq_cycle.csv, the optimum."""

def periodic(
    config: Any,
    *,
    period: Optional[int] = None,
    transient: int = 200,
    guess: Optional[Tuple[List[float], List[float]]] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    mechanics_only: bool = False,
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
    transient: Optional[int] = None,
    guess: Optional[Tuple[List[float], List[float]]] = None,
    max_points: Optional[int] = None,
    doubling_depth: Optional[int] = None,
    initial_step: Optional[float] = None,
    max_step: Optional[float] = None,
    mechanics_only: bool = False,
) -> Dict[str, Any]:
    """A continuation: the parameter's name and the branches."""

def curve(
    config: Any,
    kind: str,
    param: str,
    near: float,
    param2: str,
    from2: float,
    to2: float,
    *,
    period: Optional[int] = None,
    window: Optional[float] = None,
    transient: Optional[int] = None,
    max_points: Optional[int] = None,
    mechanics_only: bool = False,
) -> Dict[str, Any]:
    """A bifurcation curve in two keys: its points, codimension-two points and end."""

def bifmap(
    config: Any,
    x: str,
    x_values: List[float],
    y: str,
    y_values: List[float],
    *,
    seeds: int = 5,
    x_starts: int = 5,
    kinds: Optional[List[str]] = None,
    period: Optional[int] = None,
    doublings: int = 1,
    orbit_transient: int = 200,
    branch_points: int = 1000,
    curve_points: int = 200,
    max_curves: int = 64,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = 1e-4,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    floquet: bool = False,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """A bifurcation map: its curves, codimension-two and located points, power map."""

def grid(start: float, stop: float, steps: int) -> npt.NDArray[np.float64]:
    """`steps` values equally spaced from `start` to `stop` (both included, `stop` exactly)."""

def log_spaced(start: float, stop: float, steps: int) -> npt.NDArray[np.float64]:
    """`steps` values evenly spaced in the logarithm from `start` to `stop` (both exactly)."""

def chirp(
    config: Any,
    from_: float,
    to: float,
    duration: float,
    *,
    sweep: ChirpSweep = "linear",
    amplitude: Optional[float] = None,
    mechanics_only: bool = False,
    from_rest: bool = False,
    samples_per_cycle: int = 200,
    jump_window: int = 5,
) -> Dict[str, Any]:
    """The chirp experiment: the columns of response.csv, the runs up and down."""

def basins(
    config: Any,
    x: str,
    x_from: float,
    x_to: float,
    y: str,
    y_from: float,
    y_to: float,
    grid_size: Tuple[int, int],
    *,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    period_tolerance: float = 1e-4,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """Basins: the columns of basins.csv, attractors.csv and the starts."""

def attractors(
    config: Any,
    param: str,
    values: List[float],
    *,
    samples: int = 100,
    seed: int = 1,
    position_range: Optional[float] = None,
    velocity_range: Optional[float] = None,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
    continuation_distance: float = 0.25,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    period_tolerance: float = 1e-4,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """The attractor census: the columns of attractors.csv and expected_power.csv."""

def optimize(
    config: Any,
    vary: List[str],
    *,
    objective: str = ...,
    constraints: Optional[List[str]] = ...,
    starts: int = ...,
    seed: int = ...,
    particles: int = ...,
    swarm_iterations: int = ...,
    local_iterations: int = ...,
) -> Dict[str, Any]: ...
def response(
    config: Any,
    values: List[float],
    *,
    param: str = ...,
    branches: bool = ...,
    branch_seeds: int = ...,
    transient: Optional[int] = ...,
    recorded: Optional[int] = ...,
    period_tolerance: float = ...,
    settle: SettleMode = ...,
    settle_cap: int = ...,
    allow_large: bool = ...,
) -> Dict[str, Any]: ...
def band_response(
    config: Any,
    centres_hz: List[float],
    *,
    width: Optional[float] = ...,
    seeds: int = ...,
    transient: Optional[int] = ...,
    recorded: Optional[int] = ...,
    period_tolerance: float = ...,
    settle: SettleMode = ...,
    settle_cap: int = ...,
    threads: Optional[int] = ...,
    allow_large: bool = ...,
) -> Dict[str, Any]: ...
def optimize_mass_ratio(
    config: Any,
    *,
    omega_from: float = 0.55,
    omega_to: float = 0.95,
    omega_steps: int = 9,
    rm_from: float = 1.2,
    rm_to: float = 7.0,
    rm_steps: int = 59,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    period_tolerance: float = 1e-4,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """The optimal mass ratio: power_grid.csv, optimum.csv and the fits."""

def export_spice(
    config: Any,
    *,
    from_period: Optional[int] = None,
    periods: int = 2,
    dt_fraction: float = 0.0005,
    check: bool = False,
    allow_large: bool = ...,
) -> Dict[str, Any]:
    """The ngspice netlist of a run and its gap waveforms."""

DEFAULT_START_PERIODS: Tuple[int, int]

def basin_starts(
    config: Any,
    x: str,
    x_values: List[float],
    y: str,
    y_values: List[float],
    *,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    period_tolerance: float = 1e-4,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = 2000,
    threads: Optional[int] = None,
) -> List[Tuple[int, float, Optional[float], List[float], List[int], Optional[str]]]:
    """The fingerprints of a basin grid's starts (grid order), not classified."""

def classify_basins(
    config: Any,
    x_values: List[float],
    y_values: List[float],
    fingerprints: List[Tuple[int, float, Optional[float], List[float], List[int], Optional[str]]],
    *,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
) -> Dict[str, Any]:
    """The tables of a basin grid from its starts' fingerprints."""
