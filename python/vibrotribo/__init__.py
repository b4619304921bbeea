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

import collections.abc
import hashlib
import os
import tempfile
from typing import Any, Dict, Iterable, Literal, Mapping, Optional, Tuple, Union, overload

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
from ._studies import Attractors, BandResponse, Basins, Chirp, MassRatioOptimum, Response, SpiceExport
from ._curve import Curve
from ._bifmap import BifurcationMap
from ._vibrotribo import Config, OrbitNotFound, __version__, grid, log_spaced

# A Config is a read-only mapping of its effective values (cfg["excitation.amplitude"]).
collections.abc.Mapping.register(Config)

__all__ = [
    "Config",
    "simulate",
    "sweep",
    "map",
    "load_sweep",
    "periodic",
    "continue_",
    "curve",
    "Curve",
    "bifmap",
    "BifurcationMap",
    "lyapunov",
    "Lyapunov",
    "chirp",
    "Chirp",
    "basins",
    "Basins",
    "attractors",
    "Attractors",
    "optimize",
    "response",
    "Response",
    "band_response",
    "BandResponse",
    "optimize_mass_ratio",
    "MassRatioOptimum",
    "export_spice",
    "SpiceExport",
    "with_base_motion",
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
SettleMode = Literal["auto", "fixed"]
ContinuationMode = Literal["none", "up", "down"]
ChirpSweep = Literal["linear", "logarithmic"]
Quantity = Literal["displacement", "acceleration"]


@overload
def _count(value: int, name: str, *, least: int = 0) -> int: ...
@overload
def _count(value: None, name: str, *, least: int = 0) -> None: ...
@overload
def _count(value: Optional[int], name: str, *, least: int = 0) -> Optional[int]: ...
def _count(value: Optional[int], name: str, *, least: int = 0) -> Optional[int]:
    """``value`` as a whole number of at least ``least`` (None stays None), or a ValueError
    naming the argument."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be a whole number, got {value!r}")
    if value < least:
        raise ValueError(f"{name} must be at least {least}, got {value}")
    return int(value)


def _config(config: ConfigLike, allow_large: bool = False) -> Config:
    """``config`` as a :class:`Config`; with ``allow_large`` a path or dict whose random
    excitation costs more than the documented limit is built (as ``Config(...,
    allow_large=True)``), as the command line's ``--allow-large`` allows it."""
    if isinstance(config, Config) and (config.allow_large or not allow_large):
        return config
    return Config(config, allow_large=allow_large)


def _values(values: Iterable[float], name: str) -> list:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite numbers")
    return a.tolist()


def simulate(
    config: ConfigLike = None,
    *,
    mechanics_only: bool = False,
    samples: bool = True,
    settle: SettleMode = "fixed",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    allow_large: bool = False,
) -> Simulation:
    """Simulates the configuration: ``run.periods`` excitation periods from
    ``run.initial_positions``/``run.initial_velocities``, the harvester's charge solved
    alongside (unless ``mechanics_only``), sampled ``run.samples_per_period`` times per
    period (unless ``samples=False``, which leaves the sample arrays empty).

    ``config`` is a :class:`Config`, a dict shaped like the TOML file, or a path to one
    (None: the paper's default case). Returns a :class:`Simulation` whose arrays and summary
    equal what ``vibrotribo simulate --out DIR`` writes. Raises :class:`SimulationError`
    if the run fails on the way (its ``result`` holds the periods before),
    ``KeyboardInterrupt`` on Ctrl-C, ``ValueError``/``KeyError`` on bad input.

    ``settle``: ``"fixed"`` runs the configuration as it is; ``"auto"`` first settles (at
    most ``settle_cap`` periods, mechanics only, as a sweep point settles) and then runs the
    configuration from the settled state (``summary["motion"]["settle_periods"]`` says how
    many periods came before), as ``--settle``/``--settle-cap``. A run whose samples and
    per-period statistics would need more than 4 GiB is refused with ``MemoryError`` before
    anything is allocated (``allow_large=True`` runs it; ``samples=False`` keeps no samples).
    """
    cfg = _config(config, allow_large)
    raw = _vibrotribo.simulate(
        cfg,
        mechanics_only=mechanics_only,
        samples=samples,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap", least=1),
        allow_large=allow_large,
    )
    result = Simulation._from(raw, cfg)
    if raw["error"] is not None:
        raise SimulationError(raw["error"], result)
    return result


def sweep(
    config: ConfigLike,
    param: str,
    values: Iterable[float],
    *,
    continuation: ContinuationMode = "none",
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    floquet: bool = False,
    lyapunov: bool = False,
    allow_large: bool = False,
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
    point is ``periodic``, ``settling``, ``quasiperiodic`` or ``chaotic``. ``floquet``:
    also shoot each point's orbit for its largest Floquet multiplier modulus (column
    ``max_abs_multiplier``); ``lyapunov``: also estimate each point's largest Lyapunov
    exponent (columns ``lyapunov_max_1_s``, ``lyapunov_spread_1_s``), as
    ``--floquet``/``--lyapunov``. More than 10⁷ values raise ``ValueError``, an estimated
    memory above 4 GiB ``MemoryError`` (``allow_large=True`` runs it).
    """
    raw = _vibrotribo.sweep(
        _config(config, allow_large),
        param,
        _values(values, "values"),
        continuation=continuation,
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        mechanics_only=mechanics_only,
        threads=_count(threads, "threads", least=1),
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        floquet=floquet,
        lyapunov=lyapunov,
        allow_large=allow_large,
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
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    floquet: bool = False,
    allow_large: bool = False,
) -> Map:
    """A two-parameter map: every point (x, y) of the grid (y outer, x inner), each run as a
    sweep point (see :func:`sweep`); its ``summary`` is ``vibrotribo map``'s ``map.csv``.
    When an axis is an initial condition (``run.initial_positions[i]``,
    ``run.initial_velocities[i]``), a start whose masses interpenetrate is a row with its
    ``error`` (as ``vibrotribo basins`` skips it) instead of failing the map."""
    raw = _vibrotribo.map(
        _config(config, allow_large),
        x,
        _values(x_values, "x_values"),
        y,
        _values(y_values, "y_values"),
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        mechanics_only=mechanics_only,
        threads=_count(threads, "threads", least=1),
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        floquet=floquet,
        allow_large=allow_large,
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
    allow_large: bool = False,
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
        _config(config, allow_large),
        resistances=None if resistances is None else _values(resistances, "resistances"),
        low=low,
        high=high,
        steps=_count(steps, "steps", least=1),
        vq_points=_count(vq_points, "vq_points"),
        allow_large=allow_large,
    )
    return LoadSweep._from(raw)


def periodic(
    config: ConfigLike = None,
    *,
    period: Optional[int] = None,
    transient: int = 200,
    guess: Optional[tuple] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    mechanics_only: bool = False,
) -> Orbit:
    """A periodic orbit of the configuration's chain by Newton shooting on the stroboscopic
    map, and its Floquet multipliers (stable and unstable orbits alike).

    Without ``guess``: simulates ``transient`` periods from the configured initial state and
    starts Newton there, with ``period`` (in excitation periods) or, if None, the period read
    off 128 further stroboscopic samples. With ``guess=(x, v)`` (positions in m, velocities in
    m/s at t = 0) Newton starts from it (``period`` needed). ``tolerance``: scaled residual
    (default 1e-12). ``transient=0`` shoots from the configured initial state itself (period
    default 1), as ``vibrotribo periodic --transient 0``. Unless ``mechanics_only``, the
    harvester is run along the orbit: ``Orbit.average_power_w``, as ``vibrotribo periodic``
    reports it. Raises :class:`OrbitNotFound` if Newton does not converge or the motion is
    not periodic. Ctrl-C raises ``KeyboardInterrupt`` within a Newton iteration or a piece
    of the transient.
    """
    raw = _vibrotribo.periodic(
        _config(config),
        period=_count(period, "period", least=1),
        transient=_count(transient, "transient"),
        guess=None if guess is None else (list(_floats(guess[0])), list(_floats(guess[1]))),
        tolerance=tolerance,
        max_iterations=_count(max_iterations, "max_iterations", least=1),
        mechanics_only=mechanics_only,
    )
    return Orbit._from(raw)


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
    mechanics_only: bool = False,
) -> Continuation:
    """Follows the periodic orbit found at ``param = start`` (after ``transient`` periods
    from the configured initial state, default 200, as ``vibrotribo continue`` finds it; or
    near ``guess`` with ``period``) to ``param = stop`` by pseudo-arclength continuation, locating folds, period doublings
    (following the doubled branches to ``doubling_depth`` levels, default 3),
    Neimark–Sacker points, grazings and sticking onsets. ``param`` is any numeric
    configuration key or derived key. Steps are in scaled arclength (defaults: initial 0.02,
    largest 0.1); ``max_points`` per branch (default 2000). Unless ``mechanics_only``, the
    harvester's average power on every point is computed (``Branch.points["average_power_w"]``,
    as ``vibrotribo continue`` writes it in ``branch.csv``). Ctrl-C raises
    ``KeyboardInterrupt``: during the continuation, within a step (the continuation is
    stopped there); during the power, at the next point.
    """
    raw = _vibrotribo.continue_(
        _config(config),
        param,
        float(start),
        float(stop),
        period=_count(period, "period", least=1),
        transient=_count(transient, "transient"),
        guess=None if guess is None else (list(_floats(guess[0])), list(_floats(guess[1]))),
        max_points=_count(max_points, "max_points", least=1),
        doubling_depth=_count(doubling_depth, "doubling_depth"),
        initial_step=initial_step,
        max_step=max_step,
        mechanics_only=mechanics_only,
    )
    return Continuation._from(raw)


def curve(
    config: ConfigLike,
    kind: str,
    param: str,
    near: float,
    param2: str,
    from2: float,
    to2: float,
    *,
    period: Optional[int] = None,
    window: float = 0.05,
    transient: int = 200,
    max_points: int = 200,
    mechanics_only: bool = False,
) -> Curve:
    """Follows a bifurcation in two keys, as ``vibrotribo curve`` does: the bifurcation of
    ``kind`` (``fold``, ``period_doubling``, ``neimark_sacker`` or ``grazing``) nearest
    ``param = near`` on the branch (of ``period``, default that of the orbit found after
    ``transient`` periods at ``near``) is located with ``param2 = from2`` within
    ``near ± window·|near|``, then continued in (``param``, ``param2``) by pseudo-arclength
    on its defining system (orbit plus condition) until ``param2 = to2``, ``max_points``, or
    a codimension-two point where the orbit's event sequence changes. Unless
    ``mechanics_only``, the harvester's average power on every point is computed.
    """
    raw = _vibrotribo.curve(
        _config(config),
        kind,
        param,
        float(near),
        param2,
        float(from2),
        float(to2),
        period=_count(period, "period", least=1),
        window=float(window),
        transient=_count(transient, "transient"),
        max_points=_count(max_points, "max_points", least=2),
        mechanics_only=mechanics_only,
    )
    return Curve._from(raw)


def bifmap(
    config: ConfigLike,
    x: str,
    x_values: Iterable[float],
    y: str,
    y_values: Iterable[float],
    *,
    seeds: int = 5,
    x_starts: int = 5,
    kinds: Optional[Iterable[str]] = None,
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
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    floquet: bool = False,
    allow_large: bool = False,
) -> BifurcationMap:
    """A bifurcation map, as ``vibrotribo bifmap`` computes it: at ``seeds`` values of ``y``
    (equally spaced from the first to the last of ``y_values``) the periodic orbits found
    after ``orbit_transient`` periods from the configured initial state at ``x_starts``
    values of ``x`` (equally spaced over the first to the last of ``x_values``) are continued
    in ``x`` towards both ends (``doublings`` period doublings followed);
    every fold, period doubling, Neimark–Sacker point and grazing located on them (of
    ``kinds``, default all) that lies on no curve yet is followed in ``y`` towards both ends
    (``curve_points`` points per half, at most ``max_curves`` curves). The power map is
    :func:`vibrotribo.map` over ``x_values`` × ``y_values`` with the remaining settings.
    Returns a :class:`BifurcationMap` equal to the command's files."""
    raw = _vibrotribo.bifmap(
        _config(config),
        x,
        _values(x_values, "x_values"),
        y,
        _values(y_values, "y_values"),
        seeds=_count(seeds, "seeds", least=1),
        x_starts=_count(x_starts, "x_starts", least=2),
        kinds=None if kinds is None else [str(k) for k in kinds],
        period=_count(period, "period", least=1),
        doublings=_count(doublings, "doublings"),
        orbit_transient=_count(orbit_transient, "orbit_transient"),
        branch_points=_count(branch_points, "branch_points", least=2),
        curve_points=_count(curve_points, "curve_points", least=2),
        max_curves=_count(max_curves, "max_curves", least=1),
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        mechanics_only=mechanics_only,
        threads=_count(threads, "threads", least=1),
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        floquet=floquet,
        allow_large=allow_large,
    )
    return BifurcationMap._from(raw)


def lyapunov(
    config: ConfigLike = None,
    *,
    periods: int = 1000,
    transient: int = 300,
    seed: int = 1,
    batches: int = 10,
    allow_large: bool = False,
) -> Lyapunov:
    """All 2N Lyapunov exponents of the configuration's run (mechanics), through impacts,
    sticking and chatter, from the exact state-transition matrix: ``transient`` periods
    (the motion settles and the tangent vectors align), then ``periods`` averaged over in
    ``batches`` batches (the spread is their batch-means standard error). ``seed`` seeds the
    initial tangent basis. The same numbers as ``vibrotribo lyapunov``. Ctrl-C raises
    ``KeyboardInterrupt`` within a second. ``allow_large=True`` builds a random excitation
    of a path or dict past the limit of 10⁹ harmonic evaluations (as ``--allow-large``;
    ``Config(..., allow_large=True)`` does the same for a configuration made first).
    """
    raw = _vibrotribo.lyapunov(
        _config(config, allow_large),
        periods=_count(periods, "periods", least=1),
        transient=_count(transient, "transient"),
        seed=_count(seed, "seed"),
        batches=_count(batches, "batches", least=1),
    )
    return Lyapunov(**raw)



def chirp(
    config: ConfigLike,
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
) -> Chirp:
    """The frequency-sweep experiment of ``vibrotribo chirp``: the base driven by a slow
    chirp in Ω from ``from_`` to ``to`` over ``duration`` seconds, then back down; the
    response per cycle (amplitudes, impacts, power), the largest jump each way and the
    hysteresis between them (:class:`Chirp`). ``sweep``: ``"linear"`` or ``"logarithmic"``
    in frequency; ``amplitude`` the base amplitude, m (default ``excitation.amplitude``);
    each chirp starts from the steady motion at its start frequency unless ``from_rest``.
    ``samples_per_cycle`` samples per cycle at the highest frequency; the jump compares the
    median amplitudes of ``jump_window`` cycles on each side of a boundary. Raises
    :class:`SimulationError` (with the result) if a chirp fails on the way."""
    raw = _vibrotribo.chirp(
        _config(config),
        float(from_),
        float(to),
        float(duration),
        sweep=sweep,
        amplitude=amplitude,
        mechanics_only=mechanics_only,
        from_rest=from_rest,
        samples_per_cycle=_count(samples_per_cycle, "samples_per_cycle", least=1),
        jump_window=_count(jump_window, "jump_window", least=1),
    )
    result = Chirp._from(raw)
    for name in ("up", "down"):
        run = raw[name]
        if run is not None and run["failure"]:
            raise SimulationError(f"the {name} chirp stopped after {run['periods']} periods: {run['failure']}", result)  # type: ignore[arg-type]
    return result


def basins(
    config: ConfigLike,
    x: str,
    x_from: float,
    x_to: float,
    y: str,
    y_from: float,
    y_to: float,
    grid: Tuple[int, int],
    *,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> Basins:
    """Basins of attraction over two initial conditions, as ``vibrotribo basins``: ``x`` and
    ``y`` are ``run.initial_positions[i]`` (m) or ``run.initial_velocities[i]`` (m/s), i
    0-based; ``grid=(nx, ny)`` nodes from ``x_from`` to ``x_to`` and ``y_from`` to ``y_to``
    (``--grid NXxNY``). Every start runs ``transient`` (default 500) and ``recorded``
    (default 100) periods and is fingerprinted by its stroboscopic section; the starts are
    then classified in grid order, so the result does not depend on ``threads``. A start
    whose masses interpenetrate does not run (attractor −1, its ``error`` in ``starts``).
    ``cell``, ``section_tolerance`` and ``match_tolerance`` (scaled units) are those of the
    command line. Returns :class:`Basins` equal to its ``basins.csv`` and ``attractors.csv``."""
    nx, ny = grid
    raw = _vibrotribo.basins(
        _config(config, allow_large),
        x,
        float(x_from),
        float(x_to),
        y,
        float(y_from),
        float(y_to),
        (_count(nx, "grid[0]", least=1), _count(ny, "grid[1]", least=1)),
        cell=cell,
        section_tolerance=section_tolerance,
        match_tolerance=match_tolerance,
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        mechanics_only=mechanics_only,
        period_tolerance=period_tolerance,
        floquet=floquet,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        threads=_count(threads, "threads", least=1),
        allow_large=allow_large,
    )
    return Basins._from(raw)


def attractors(
    config: ConfigLike,
    param: str,
    values: Iterable[float],
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
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> Attractors:
    """The attractors of ``samples`` random starts at each of ``values`` of ``param``, as
    ``vibrotribo attractors`` (``values=vt.grid(from, to, steps)``): starts uniform in
    ±``position_range`` (m; default the base amplitude) and ±``velocity_range`` (m/s; default
    its peak speed), the same starts at every value (``seed``); each value's attractors
    with their basin fractions and power, followed from value to value, and the expected
    power of an unknown start (:class:`Attractors`)."""
    raw = _vibrotribo.attractors(
        _config(config, allow_large),
        param,
        _values(values, "values"),
        samples=_count(samples, "samples", least=1),
        seed=_count(seed, "seed"),
        position_range=position_range,
        velocity_range=velocity_range,
        cell=cell,
        section_tolerance=section_tolerance,
        match_tolerance=match_tolerance,
        continuation_distance=continuation_distance,
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        mechanics_only=mechanics_only,
        period_tolerance=period_tolerance,
        floquet=floquet,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        threads=_count(threads, "threads", least=1),
        allow_large=allow_large,
    )
    return Attractors._from(raw)


def optimize(
    config: ConfigLike = None,
    vary: Iterable[str] = (),
    *,
    objective: Literal["average_power", "expected_power", "power_per_mass"] = "average_power",
    constraint: Iterable[str] = (),
    starts: int = 4,
    seed: int = 0,
    particles: int = 8,
    swarm_iterations: int = 6,
    local_iterations: int = 30,
) -> dict:
    """A design optimised over configuration keys, as ``vibrotribo optimize``: ``vary`` as
    ``["KEY=LO..HI", …]`` (a key spanning two decades or more is searched on a log scale),
    ``objective`` to maximise, ``constraint`` as ``["breakdown_ratio<=0.9",
    "max_displacement<=0.05", …]``; a seeded particle swarm then Nelder–Mead (argmin).
    Returns a dict with ``best`` (key → value), ``objective`` (W, or W/kg for
    ``power_per_mass``), its ``objective_standard_error``, ``breakdown_ratio``,
    ``max_displacement_m``, ``evaluations``, ``history`` and ``best_config`` (the best
    design as TOML, which ``vibrotribo simulate`` runs to the same power)."""
    vary = [str(v) for v in vary]
    if not vary:
        raise ValueError("vary: give at least one KEY=LO..HI")
    return _vibrotribo.optimize(
        _config(config),
        vary,
        objective=objective,
        constraints=[str(c) for c in constraint],
        starts=_count(starts, "starts", least=1),
        seed=_count(seed, "seed"),
        particles=_count(particles, "particles", least=1),
        swarm_iterations=_count(swarm_iterations, "swarm_iterations"),
        local_iterations=_count(local_iterations, "local_iterations"),
    )


def response(
    config: ConfigLike,
    values: Iterable[float],
    *,
    param: str = "excitation.omega_ratio",
    branches: bool = False,
    branch_seeds: int = 8,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    allow_large: bool = False,
) -> Response:
    """The frequency response of ``vibrotribo response``: average power against ``param``
    over ``values`` (increasing; ``values=vt.grid(from, to, steps)``) from an up sweep (the
    values in order) and a down sweep (in reverse), each value started from the final state
    of the one before, so that coexisting motions show as hysteresis; with ``branches`` the
    branches of periodic orbits through the periodic motions the sweeps found are followed
    by continuation (at most ``branch_seeds`` seeds), with the power on every point. The peak
    and the half-power band of each sweep, each branch and their envelope are in
    ``summary`` (:class:`Response`). The same numbers as the command's files. Ctrl-C raises
    ``KeyboardInterrupt``."""
    raw = _vibrotribo.response(
        _config(config),
        _values(values, "values"),
        param=param,
        branches=branches,
        branch_seeds=_count(branch_seeds, "branch_seeds", least=1),
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        allow_large=allow_large,
    )
    return Response._from(raw)


def band_response(
    config: ConfigLike,
    centres_hz: Iterable[float],
    *,
    width: Optional[float] = None,
    seeds: int = 8,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> BandResponse:
    """The response to band-limited random input of ``vibrotribo band-response``: the
    configuration's flat-spectrum noise (``excitation.kind = "random"`` with
    ``rms_acceleration``, ``f_low_hz``, ``f_high_hz``) moved to the band ``width`` Hz wide
    (default: the configured one) centred on each of ``centres_hz`` (increasing), at the same
    RMS acceleration, run with ``seeds`` seeds from ``excitation.seed`` on; the power is the
    mean over the seeds with its standard error, and the peak and half-power band of the mean
    are in ``summary`` (:class:`BandResponse`). The same numbers as the command's files."""
    raw = _vibrotribo.band_response(
        _config(config),
        _values(centres_hz, "centres_hz"),
        width=width,
        seeds=_count(seeds, "seeds", least=1),
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        threads=_count(threads, "threads", least=1),
        allow_large=allow_large,
    )
    return BandResponse._from(raw)


def optimize_mass_ratio(
    config: ConfigLike = None,
    *,
    omega_from: float = 0.55,
    omega_to: float = 0.95,
    omega_steps: int = 9,
    rm_from: float = 1.2,
    rm_to: float = 7.0,
    rm_steps: int = 59,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    floquet: bool = False,
    settle: SettleMode = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    threads: Optional[int] = None,
    allow_large: bool = False,
) -> MassRatioOptimum:
    """The optimal mass ratio R_mo(Ω) = m₂/m₁ (m₁ and m₃ fixed) of the paper's Fig. 16, as
    ``vibrotribo optimize-mass-ratio``: the average power on ``omega_steps`` values of Ω
    from ``omega_from`` to ``omega_to`` × ``rm_steps`` mass ratios from ``rm_from`` to
    ``rm_to``, the best ratio at each Ω refined by a parabola, and a quadratic fit through
    them compared with the paper's (:class:`MassRatioOptimum`)."""
    raw = _vibrotribo.optimize_mass_ratio(
        _config(config, allow_large),
        omega_from=float(omega_from),
        omega_to=float(omega_to),
        omega_steps=_count(omega_steps, "omega_steps", least=1),
        rm_from=float(rm_from),
        rm_to=float(rm_to),
        rm_steps=_count(rm_steps, "rm_steps", least=1),
        transient=_count(transient, "transient"),
        recorded=_count(recorded, "recorded"),
        period_tolerance=period_tolerance,
        floquet=floquet,
        settle=settle,
        settle_cap=_count(settle_cap, "settle_cap"),
        threads=_count(threads, "threads", least=1),
        allow_large=allow_large,
    )
    return MassRatioOptimum._from(raw)


def export_spice(
    config: Union[ConfigLike, Simulation],
    *,
    from_period: Optional[int] = None,
    periods: int = 2,
    dt_fraction: float = 0.0005,
    check: bool = False,
    allow_large: bool = False,
) -> SpiceExport:
    """An ngspice netlist of the harvester of a run (a :class:`Simulation` or its
    configuration), driven by the run's gap waveforms over ``periods`` excitation periods
    from ``from_period`` (default: the first after the transient), sampled every
    ``dt_fraction`` of a period (every impact also a breakpoint): the text ``vibrotribo
    export-spice RUN_DIR`` writes for the same run. ``check=True`` also runs ngspice and
    compares the energy delivered (:class:`SpiceExport`). ``result.write(path)`` writes it."""
    cfg = config.config if isinstance(config, Simulation) else _config(config, allow_large)
    raw = _vibrotribo.export_spice(
        cfg,
        from_period=_count(from_period, "from_period"),
        periods=_count(periods, "periods", least=1),
        dt_fraction=float(dt_fraction),
        check=check,
        allow_large=allow_large,
    )
    fields: Dict[str, Any] = {k: (tuple(v) if k == "window_s" else v) for k, v in raw.items()}
    return SpiceExport(**fields)


def with_base_motion(
    config: ConfigLike,
    times: Iterable[float],
    values: Iterable[float],
    quantity: Quantity = "acceleration",
    *,
    directory: Optional[Union[str, "os.PathLike[str]"]] = None,
    **scaling: Any,
) -> Config:
    """``config`` driven by a recorded base motion given as arrays: ``times`` (s, increasing)
    and ``values`` (the base ``quantity``: ``"acceleration"`` in m/s², integrated exactly and
    baseline-corrected, or ``"displacement"`` in m), as ``excitation.kind = "record"`` reads
    it from a file. The samples are written once, exactly (shortest round-trip decimals),
    to a file named by their hash in ``directory`` (default: a ``vibrotribo-records`` folder
    in the temporary directory), so that the configuration pickles (to Dask workers on the
    same machine or a shared file system) and equals the command line's run of that file.
    ``scaling`` takes the record's other keys (``peak_acceleration=9.8``,
    ``omega_ratio=0.7`` for the reference period, …)."""
    t = np.asarray(times, dtype=float)
    y = np.asarray(values, dtype=float)
    if t.ndim != 1 or y.shape != t.shape or t.size < 2:
        raise ValueError(
            f"times and values must be 1-D arrays of the same length (at least 2), got shapes {t.shape} and {y.shape}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise ValueError("times and values must be finite numbers")
    if not np.all(np.diff(t) > 0):
        raise ValueError("times must be strictly increasing")
    if quantity not in ("acceleration", "displacement"):
        raise ValueError(f'quantity must be "acceleration" or "displacement", got {quantity!r}')
    column = "acceleration_m_s2" if quantity == "acceleration" else "displacement_m"
    text = f"time_s,{column}\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), y.tolist()))
    folder = os.fspath(directory) if directory is not None else os.path.join(tempfile.gettempdir(), "vibrotribo-records")
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, hashlib.sha256(text.encode()).hexdigest()[:24] + ".csv")
    if not os.path.exists(path):
        part = path + f".{os.getpid()}.part"
        with open(part, "w") as f:
            f.write(text)
        os.replace(part, path)
    keys = {"excitation.kind": "record", "excitation.file": os.path.abspath(path), "excitation.quantity": quantity}
    keys.update({f"excitation.{k}": v for k, v in scaling.items()})
    return _config(config).replace(**keys)

def _floats(values: Iterable[float]) -> list:
    """``values`` as a list of Python floats."""
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


def __getattr__(name: str) -> Any:
    # `vibrotribo.dask` without importing dask until it is used.
    if name == "dask":
        import importlib

        return importlib.import_module(".dask", __name__)
    raise AttributeError(f"module 'vibrotribo' has no attribute {name!r}")
