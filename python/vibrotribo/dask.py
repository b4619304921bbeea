"""Sweeps, maps and basins spread over a Dask cluster: ``vibrotribo.dask.sweep(client,
config, param, values, ...)`` splits the values into chunks, runs each chunk as one task
calling the serial :func:`vibrotribo.sweep` on a worker, and joins the chunks in order, so
that it returns exactly what the serial ``vibrotribo.sweep`` returns for the same arguments
(every point of a sweep without continuation is independent of the others and of the thread
count). ``vibrotribo.dask.map`` spreads the rows of a map the same way, and
``vibrotribo.dask.basins`` the rows of a basin grid (the starts run on the workers; their
fingerprints are classified here, in grid order, so the result equals the serial
:func:`vibrotribo.basins`).

Ctrl-C (``KeyboardInterrupt``) while waiting cancels every submitted task before it is
raised, so that the workers stop instead of finishing work nobody will collect.

Needs ``dask[distributed]`` (and, on Slurm, ``dask-jobqueue``); nothing from dask is
imported until a sweep is submitted::

    from dask.distributed import Client
    from dask_jobqueue import SLURMCluster
    import vibrotribo as vt, vibrotribo.dask

    cluster = SLURMCluster(cores=4, memory="8GB", walltime="01:00:00")
    cluster.scale(jobs=16)
    client = Client(cluster)
    result = vibrotribo.dask.sweep(client, "configs/chatter.toml", "omega_ratio",
                                   vt.grid(0.3, 1.0, 20000), transient=300, recorded=100)
"""

from __future__ import annotations

import math
import time
from typing import Any, Dict, Iterable, List, Optional

import numpy as np

from . import Basins, Config, Map, Sweep, Table, _config, _values, _vibrotribo
from . import map as _serial_map
from . import sweep as _serial_sweep

__all__ = ["sweep", "map", "basins"]

_POLL_S = 0.05
"""How often the waiting loop looks at the futures, s."""


def _gather(client: Any, futures: List[Any]) -> List[Any]:
    """The results of ``futures`` in order; on an interrupt or an error the futures not yet
    done are cancelled first (the workers stop), then the exception is raised.

    The waiting happens here, in Python, until every future is done (or one failed): a
    Ctrl-C then lands in this loop, not inside the client's gathering coroutine, which an
    interrupt would leave behind with a "Task exception was never retrieved"."""
    try:
        i = 0
        while i < len(futures):
            f = futures[i]
            if f.status == "error":
                break  # gather raises its exception
            if f.done():
                i += 1
            else:
                time.sleep(_POLL_S)
        return client.gather(futures)
    except BaseException:
        client.cancel(futures, force=True)
        raise


def _chunk_size(client: Any, n: int, chunk_size: Optional[int]) -> int:
    if chunk_size is None:
        workers = sum(client.nthreads().values()) or 1
        return max(1, math.ceil(n / (4 * workers)))
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, got {chunk_size}")
    return chunk_size


def _run_chunk(config: Config, param: str, values: List[float], kwargs: dict) -> Sweep:
    """One task: the serial sweep of ``values``."""
    return _serial_sweep(config, param, values, **kwargs)


def sweep(
    client: Any,
    config: Any,
    param: str,
    values: Iterable[float],
    *,
    continuation: str = "none",
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = 1,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: str = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    chunk_size: Optional[int] = None,
) -> Sweep:
    """:func:`vibrotribo.sweep` with its values spread over the workers of the Dask
    ``client``: chunks of ``chunk_size`` values (default: about four chunks per worker
    thread) each run as one task with ``threads`` threads (default 1: one value at a time per
    Dask worker thread; the GIL is released while it computes). Returns exactly what the
    serial sweep returns for the same arguments.

    ``continuation`` must be ``"none"``: a continued sweep is one chain of values, each
    starting from the previous one's final state, and cannot be split. Bad input (an unknown
    key, a bad value) raises here, before anything is submitted.
    """
    if continuation != "none":
        raise ValueError(
            f"vibrotribo.dask.sweep: continuation={continuation!r} cannot be spread over a "
            "cluster (each value starts from the previous one's final state, one chain); "
            "use vibrotribo.sweep for continued sweeps, or continuation='none'"
        )
    cfg = _config(config)
    vals = _values(values, "values")
    kwargs: Dict[str, Any] = dict(
        transient=transient,
        recorded=recorded,
        mechanics_only=mechanics_only,
        threads=threads,
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=settle_cap,
    )
    if not vals:
        return _serial_sweep(cfg, param, vals, **kwargs)
    # Fail early and here, not on a worker, on a bad key or value (as the serial sweep does).
    _check(cfg, param, vals)
    chunk_size = _chunk_size(client, len(vals), chunk_size)
    chunks = [vals[j : j + chunk_size] for j in range(0, len(vals), chunk_size)]
    futures = client.map(
        _run_chunk,
        [cfg] * len(chunks),
        [param] * len(chunks),
        chunks,
        [kwargs] * len(chunks),
        pure=False,
    )
    parts: List[Sweep] = _gather(client, futures)
    # The whole sweep's axis (sweep.json's param, from, to, steps, values).
    settings = dict(parts[0].settings, values=vals, steps=len(vals))
    settings["from"], settings["to"] = vals[0], vals[-1]
    return Sweep(
        summary=Table.concat([p.summary for p in parts]),
        orbit=Table.concat([p.orbit for p in parts]),
        impacts=Table.concat([p.impacts for p in parts]),
        settings=settings,
    )


def _check(config: Config, param: str, values: List[float]) -> None:
    """Raises the serial sweep's KeyError/ValueError for a bad key or value."""
    for v in values:
        config.replace(**{param: v})


def _run_map_rows(config: Config, x: str, x_values: List[float], y: str, y_values: List[float], kwargs: dict) -> Map:
    """One task: the serial map of some rows."""
    return _serial_map(config, x, x_values, y, y_values, **kwargs)


def map(  # noqa: A001 - the command's name
    client: Any,
    config: Any,
    x: str,
    x_values: Iterable[float],
    y: str,
    y_values: Iterable[float],
    *,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    threads: Optional[int] = 1,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    settle: str = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    floquet: bool = False,
    chunk_size: Optional[int] = None,
) -> Map:
    """:func:`vibrotribo.map` with its rows (values of ``y``) spread over the workers of the
    Dask ``client``, ``chunk_size`` rows per task. Returns exactly what the serial map
    returns for the same arguments."""
    cfg = _config(config)
    xs, ys = _values(x_values, "x_values"), _values(y_values, "y_values")
    kwargs: Dict[str, Any] = dict(
        transient=transient,
        recorded=recorded,
        mechanics_only=mechanics_only,
        threads=threads,
        period_tolerance=period_tolerance,
        settle=settle,
        settle_cap=settle_cap,
        floquet=floquet,
    )
    if not xs or not ys:
        return _serial_map(cfg, x, xs, y, ys, **kwargs)
    # Fail early and here on a bad key or value: a map of the first row's first point.
    _serial_map(cfg, x, xs[:1], y, ys[:1], **dict(kwargs, transient=0, recorded=1, settle="fixed"))
    size = _chunk_size(client, len(ys), chunk_size)
    rows = [ys[j : j + size] for j in range(0, len(ys), size)]
    futures = client.map(
        _run_map_rows,
        [cfg] * len(rows),
        [x] * len(rows),
        [xs] * len(rows),
        [y] * len(rows),
        rows,
        [kwargs] * len(rows),
        pure=False,
    )
    parts: List[Map] = _gather(client, futures)
    settings = dict(parts[0].settings)
    settings["y_values"] = ys
    return Map(summary=Table.concat([p.summary for p in parts]), settings=settings)



def _basin_row(config: Config, x: str, xs: List[float], y: str, y_value: float, kwargs: dict) -> list:
    """One task: the fingerprints of the starts of one row of a basin grid."""
    return _vibrotribo.basin_starts(config, x, xs, y, [y_value], **kwargs)


def basins(
    client: Any,
    config: Any,
    x: str,
    x_from: float,
    x_to: float,
    y: str,
    y_from: float,
    y_to: float,
    grid: tuple,
    *,
    cell: float = 0.05,
    section_tolerance: float = 1e-3,
    match_tolerance: float = 3e-3,
    transient: Optional[int] = None,
    recorded: Optional[int] = None,
    mechanics_only: bool = False,
    period_tolerance: float = _vibrotribo.DEFAULT_PERIOD_TOLERANCE,
    floquet: bool = False,
    settle: str = "auto",
    settle_cap: int = _vibrotribo.DEFAULT_SETTLE_CAP,
    threads: Optional[int] = 1,
) -> Basins:
    """:func:`vibrotribo.basins` with the rows of its grid spread over the workers of the Dask
    ``client``, one task per row (``threads`` threads each, default 1). The starts'
    fingerprints come back and are classified here, in grid order, so the result equals the
    serial :func:`vibrotribo.basins` for the same arguments. Bad input raises here, before
    anything is submitted (a serial run of the grid's first start checks it)."""
    from . import _count, basins as _serial_basins

    cfg = _config(config)
    nx, ny = _count(grid[0], "grid[0]", least=1), _count(grid[1], "grid[1]", least=1)
    options: Dict[str, Any] = dict(cell=cell, section_tolerance=section_tolerance, match_tolerance=match_tolerance)
    run: Dict[str, Any] = dict(
        transient=transient,
        recorded=recorded,
        mechanics_only=mechanics_only,
        period_tolerance=period_tolerance,
        floquet=floquet,
        settle=settle,
        settle_cap=settle_cap,
    )
    # Checks every argument as the serial function does, on one start (whose settings are the
    # grid's but for its axes).
    probe = _serial_basins(cfg, x, x_from, x_from, y, y_from, y_from, (1, 1), **options, **run, threads=1)
    xs = _vibrotribo.grid(float(x_from), float(x_to), int(nx)).tolist()
    ys = _vibrotribo.grid(float(y_from), float(y_to), int(ny)).tolist()
    kwargs: Dict[str, Any] = dict(options, **run, threads=threads)
    futures = client.map(
        _basin_row,
        [cfg] * len(ys),
        [x] * len(ys),
        [xs] * len(ys),
        [y] * len(ys),
        ys,
        [kwargs] * len(ys),
        pure=False,
    )
    rows: List[list] = _gather(client, futures)
    raw = _vibrotribo.classify_basins(cfg, xs, ys, [f for row in rows for f in row], **options)
    settings = dict(probe.settings, x_values=xs, y_values=ys)
    return Basins(Table(raw["basins"]), Table(raw["attractors"]), Table(raw["starts"]), settings)
