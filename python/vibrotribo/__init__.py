"""vibrotribo: exact, event-driven simulation of vibro-impact triboelectric energy
harvesters (a chain of masses on springs driven through a common base, colliding with
their neighbours, with a triboelectric generator), from Python.

A short tour (SI units throughout: kg, m, s, N/m, Ω, F, W)::

    import vibrotribo as vt

    cfg = vt.Config("configs/chatter.toml", excitation__omega_ratio=0.6)
    run = vt.simulate(cfg)                   # samples, events, summary
    run.t, run.x, run.d, run.i               # numpy arrays: s, m (samples × N), m, A
    run.summary["average_power_w"]           # the keys of summary.json

    sw = vt.sweep(cfg, "omega_ratio", vt.grid(0.3, 1.0, 200), transient=300, recorded=100)
    sw.summary["average_power_w"]            # the columns of summary.csv
    sw.orbit.to_pandas()                     # orbit.csv as a DataFrame

    orbit = vt.periodic(vt.Config())         # a periodic orbit and its Floquet multipliers
    branch = vt.continue_(vt.Config(), "omega_ratio", 0.7, 0.9)

    from dask.distributed import Client
    import vibrotribo.dask
    vibrotribo.dask.sweep(Client(), cfg, "omega_ratio", vt.grid(0.3, 1.0, 20000))

Everything runs in the Rust library with the GIL released; Ctrl-C stops a run at its next
checkpoint (a period of a run, a chunk of sweep points) and raises KeyboardInterrupt.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Mapping, Optional, Union

import numpy as np

from . import _vibrotribo
from ._results import (
    Branch,
    Continuation,
    Events,
    LoadSweep,
    Lyapunov,
    Map,
    Orbit,
    Simulation,
    SimulationError,
    Sweep,
    Table,
)
from ._vibrotribo import Config, OrbitNotFound, __version__, grid, log_spaced

__all__ = [
    "Config",
    "simulate",
    "sweep",
    "map",
    "load_sweep",
    "periodic",
    "continue_",
    "lyapunov",
    "Lyapunov",
    "grid",
    "log_spaced",
    "Simulation",
    "SimulationError",
    "Events",
    "Sweep",
    "Map",
    "LoadSweep",
    "Table",
    "Orbit",
    "Branch",
    "Continuation",
    "OrbitNotFound",
    "__version__",
]

ConfigLike = Union[Config, Mapping[str, Any], str, "os.PathLike[str]", None]


def _config(config: ConfigLike) -> Config:
    return config if isinstance(config, Config) else Config(config)


def _values(values: Iterable[float], name: str) -> list:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite numbers")
    return a.tolist()


def simulate(config: ConfigLike = None, *, mechanics_only: bool = False, samples: bool = True) -> Simulation:
    """Simulates the configuration: ``run.periods`` excitation periods from
    ``run.initial_positions``/``run.initial_velocities``, the harvester's charge solved
    alongside (unless ``mechanics_only``), sampled ``run.samples_per_period`` times per
    period (unless ``samples=False``, which leaves the sample arrays empty).

    ``config`` is a :class:`Config`, a dict shaped like the TOML file, or a path to one
    (None: the paper's default case). Returns a :class:`Simulation` whose arrays and summary
    equal what ``vibrotribo simulate --out DIR`` writes. Raises :class:`SimulationError`
    if the run fails on the way (its ``result`` holds the periods before),
    ``KeyboardInterrupt`` on Ctrl-C, ``ValueError``/``KeyError`` on bad input.
    """
    cfg = _config(config)
    raw = _vibrotribo.simulate(cfg, mechanics_only=mechanics_only, samples=samples)
    result = Simulation._from(raw, cfg)
    if raw["error"] is not None:
        raise SimulationError(raw["error"], result)
    return result


def sweep(
    config: ConfigLike,
    param: str,
    values: Iterable[float],
    *,
    continuation: str = "none",
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: str = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
) -> Sweep:
    """A one-parameter sweep: the configuration with ``param`` set to each of ``values``,
    simulated for ``transient`` periods (default ``run.transient_periods``) and then
    ``recorded`` periods (default the rest of ``run.periods``), condensed into the tables
    of ``vibrotribo sweep`` (:class:`Sweep`).

    ``param`` is any configuration key (``excitation.omega_ratio``, ``oscillator.gaps[1]``,
    ``harvester.load_resistance``) or derived key (``omega_ratio``, ``mass_ratio``,
    ``gap_ratio``, ``gap``, ``amplitude``, ``restitution``). ``continuation``: ``"none"``
    (every value from the configured initial state, in parallel on ``threads`` threads,
    default all cores), ``"up"`` or ``"down"`` (values in increasing/decreasing order, each
    from the previous one's final state). ``vibrotribo.grid(a, b, n)`` gives the values of
    ``--from a --to b --steps n``. The tables equal the command line's files for the same
    settings, whatever the thread count. An unknown key raises ``KeyError``, a value that
    makes a bad configuration ``ValueError`` (before anything runs); a point that fails on
    the way is a row with its ``error``. ``settle``: ``"auto"`` (each point runs until its
    motion repeats, at most ``settle_cap`` periods, then ``recorded`` periods; see the
    README's "How a point is classified") or ``"fixed"`` (exactly ``transient`` periods
    first), as ``--settle``/``--settle-cap``; the summary's ``motion`` column says whether a
    point is ``periodic``, ``settling``, ``quasiperiodic`` or ``chaotic``.
    """
    raw = _vibrotribo.sweep(
        _config(config),
        param,
        _values(values, "values"),
        continuation=continuation,
        transient=transient,
        recorded=recorded,
        mechanics_only=mechanics_only,
        threads=threads,
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=settle_cap,
    )
    return Sweep._from(raw)


def map(  # noqa: A001 - the command's name
    config: ConfigLike,
    x: str,
    x_values: Iterable[float],
    y: str,
    y_values: Iterable[float],
    *,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: str = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
) -> Map:
    """A two-parameter map: every point (x, y) of the grid (y outer, x inner), each run as a
    sweep point (see :func:`sweep`); its ``summary`` is ``vibrotribo map``'s ``map.csv``."""
    raw = _vibrotribo.map(
        _config(config),
        x,
        _values(x_values, "x_values"),
        y,
        _values(y_values, "y_values"),
        transient=transient,
        recorded=recorded,
        mechanics_only=mechanics_only,
        threads=threads,
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=settle_cap,
    )
    return Map._from(raw)


def load_sweep(
    config: ConfigLike = None,
    *,
    resistances: Optional[Iterable[float]] = None,
    low: float = 1e3,
    high: float = 1e13,
    steps: int = 41,
    vq_points: Optional[int] = 400,
) -> LoadSweep:
    """Average power against the load resistance: the configuration's mechanics simulated
    once (``run.periods``), the charge of its harvester with a resistor of each resistance
    (Ω; default ``steps`` log-spaced from ``low`` to ``high``, as ``vibrotribo load-sweep``)
    solved along it, the optimum refined, the power at the configured load, and the V–Q
    cycles of the last period at the configured and optimal loads (``vq_points`` points;
    None for none). Under ``harvester.coupling = "two_way"`` every load is a whole coupled
    run instead (the power at a load is what :func:`simulate` reports with it). Returns a
    :class:`LoadSweep` equal to the command's files."""
    raw = _vibrotribo.load_sweep(
        _config(config),
        resistances=None if resistances is None else _values(resistances, "resistances"),
        low=low,
        high=high,
        steps=steps,
        vq_points=vq_points,
    )
    return LoadSweep._from(raw)


def periodic(
    config: ConfigLike = None,
    *,
    period: Optional[int] = None,
    transient: int = 100,
    guess: Optional[tuple] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
) -> Orbit:
    """A periodic orbit of the configuration's chain by Newton shooting on the stroboscopic
    map, and its Floquet multipliers (stable and unstable orbits alike).

    Without ``guess``: simulates ``transient`` periods from the configured initial state and
    starts Newton there, with ``period`` (in excitation periods) or, if None, the period read
    off 128 further stroboscopic samples. With ``guess=(x, v)`` (positions in m, velocities in
    m/s at t = 0) Newton starts from it (``period`` needed). ``tolerance``: scaled residual
    (default 1e-12). Raises :class:`OrbitNotFound` if Newton does not converge or the motion
    is not periodic.
    """
    raw = _vibrotribo.periodic(
        _config(config),
        period=period,
        transient=transient,
        guess=None if guess is None else (list(_floats(guess[0])), list(_floats(guess[1]))),
        tolerance=tolerance,
        max_iterations=max_iterations,
    )
    return Orbit(**raw)


def continue_(
    config: ConfigLike,
    param: str,
    start: float,
    stop: float,
    *,
    period: Optional[int] = None,
    transient: Optional[int] = None,
    guess: Optional[tuple] = None,
    max_points: Optional[int] = None,
    doubling_depth: Optional[int] = None,
    initial_step: Optional[float] = None,
    max_step: Optional[float] = None,
) -> Continuation:
    """Follows the periodic orbit found at ``param = start`` (after ``transient`` periods
    from the configured initial state, default 200, as ``vibrotribo continue`` finds it; or
    near ``guess`` with ``period``) to ``param = stop`` by pseudo-arclength continuation, locating folds, period doublings
    (following the doubled branches to ``doubling_depth`` levels, default 3),
    Neimark–Sacker points, grazings and sticking onsets. ``param`` is any numeric
    configuration key or derived key. Steps are in scaled arclength (defaults: initial 0.02,
    largest 0.1); ``max_points`` per branch (default 2000). Interrupting takes effect only
    when it returns.
    """
    raw = _vibrotribo.continue_(
        _config(config),
        param,
        float(start),
        float(stop),
        period=period,
        transient=transient,
        guess=None if guess is None else (list(_floats(guess[0])), list(_floats(guess[1]))),
        max_points=max_points,
        doubling_depth=doubling_depth,
        initial_step=initial_step,
        max_step=max_step,
    )
    return Continuation._from(raw)


def lyapunov(
    config: ConfigLike = None,
    *,
    periods: int = 1000,
    transient: int = 300,
    seed: int = 1,
    batches: int = 10,
) -> Lyapunov:
    """All 2N Lyapunov exponents of the configuration's run (mechanics), through impacts,
    sticking and chatter, from the exact state-transition matrix: ``transient`` periods
    (the motion settles and the tangent vectors align), then ``periods`` averaged over in
    ``batches`` batches (the spread is their batch-means standard error). ``seed`` seeds the
    initial tangent basis. The same numbers as ``vibrotribo lyapunov``. Ctrl-C raises
    ``KeyboardInterrupt`` within a second.
    """
    raw = _vibrotribo.lyapunov(
        _config(config), periods=int(periods), transient=int(transient), seed=int(seed), batches=int(batches)
    )
    return Lyapunov(**raw)


def _floats(values: Iterable[float]) -> list:
    """``values`` as a list of Python floats."""
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


def __getattr__(name: str):
    # `vibrotribo.dask` without importing dask until it is used.
    if name == "dask":
        import importlib

        return importlib.import_module(".dask", __name__)
    raise AttributeError(f"module 'vibrotribo' has no attribute {name!r}")
