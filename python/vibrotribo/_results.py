"""Result objects of vibrotribo's Python API: numpy arrays with the units in their docs,
column names as in the command line's CSV files, and ``to_pandas()`` where pandas is
installed. All of them pickle (Dask sends them between processes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Iterator, List, Mapping, Optional

import numpy as np

if TYPE_CHECKING:  # pandas is optional: only to_pandas() needs it
    import pandas

from ._display import Display

__all__ = [
    "Table",
    "Events",
    "Simulation",
    "SimulationError",
    "Sweep",
    "Map",
    "LoadSweep",
    "Orbit",
    "Branch",
    "Continuation",
]


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_pandas() needs pandas: pip install pandas") from e
    return pandas


def _column(values: Any) -> np.ndarray:
    """A column as a numpy array: lists of text as a str array."""
    if isinstance(values, np.ndarray):
        return values
    if isinstance(values, list) and all(isinstance(v, str) for v in values):
        return np.array(values, dtype=str)
    return np.asarray(values)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal dtype, shape and values, NaN equal to NaN (floats compared bit for bit)."""
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a.view(np.uint8), b.view(np.uint8)))
    return bool(np.array_equal(a, b))


class Table(Mapping[str, np.ndarray]):
    """Named columns of equal length, in the order and with the names of the corresponding
    CSV file of the command line (``summary.csv``, ``orbit.csv``, ``impacts.csv``,
    ``map.csv``). ``table["average_power_w"]`` or ``table.average_power_w`` is a numpy
    array; numbers are float64 (NaN where the file leaves a cell empty), counts int64, flags
    bool, text str. ``len(table)`` is the number of columns, ``table.rows`` of rows."""

    def __init__(self, columns: Mapping[str, Any]):
        self._columns: Dict[str, np.ndarray] = {k: _column(v) for k, v in columns.items()}

    def __getitem__(self, name: str) -> np.ndarray:
        return self._columns[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._columns)

    def __len__(self) -> int:
        return len(self._columns)

    def __getattr__(self, name: str) -> np.ndarray:
        columns = self.__dict__.get("_columns", {})
        if name in columns:
            return columns[name]
        raise AttributeError(name)

    def __getstate__(self) -> Dict[str, np.ndarray]:
        return self._columns

    def __setstate__(self, state: Dict[str, np.ndarray]) -> None:
        self._columns = state

    @property
    def columns(self) -> List[str]:
        """The column names, in order."""
        return list(self._columns)

    @property
    def rows(self) -> int:
        """Number of rows."""
        return len(next(iter(self._columns.values()))) if self._columns else 0

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Table):
            return NotImplemented
        return self.columns == other.columns and all(
            _same(self[k], other[k]) for k in self._columns
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        names = ", ".join(self.columns)
        if len(names) > 200:
            names = names[:197] + "..."
        return f"Table({self.rows} rows: {names})"

    def _repr_html_(self) -> str:
        try:
            return self.to_pandas().head(10)._repr_html_()  # type: ignore[no-any-return]
        except ImportError:  # pragma: no cover - without pandas
            return "<pre>" + repr(self) + "</pre>"

    def to_pandas(self) -> "pandas.DataFrame":
        """The table as a pandas DataFrame (same column names)."""
        return _pandas().DataFrame(dict(self._columns))

    @staticmethod
    def concat(tables: List["Table"]) -> "Table":
        """The rows of ``tables`` (same columns) one after the other."""
        if not tables:
            raise ValueError("Table.concat needs at least one table")
        names = tables[0].columns
        for t in tables[1:]:
            if t.columns != names:
                raise ValueError(f"tables with different columns: {names} and {t.columns}")
        return Table({k: np.concatenate([t[k] for t in tables]) for k in names})


def _numbered(prefix: str, n: int, suffix: str) -> List[str]:
    return [f"{prefix}{i}{suffix}" for i in range(1, n + 1)]


@dataclass(frozen=True, eq=False, repr=False)
class Events(Display):
    """The events of a run, one entry per event, in time order.

    Attributes:
        t: time, s.
        kind: ``"impact"``, ``"stick"``, ``"release"`` or ``"chatter"`` (an accumulation
            point, followed by a stick or release at the same time).
        contact: contact k (1-based, as in the files): the gap between masses k and k+1.
        speed_before: closing speed just before an impact, m/s (0 for other events).
        speed_after: opening speed just after an impact, m/s (0 for other events).
        sequence_impacts: impacts resolved one by one in a chatter sequence before the jump.
        x: positions just after the event, m, shape (events, N).
        v: velocities just after the event, m/s, shape (events, N).
    """

    t: np.ndarray
    kind: np.ndarray
    contact: np.ndarray
    speed_before: np.ndarray
    speed_after: np.ndarray
    sequence_impacts: np.ndarray
    x: np.ndarray
    v: np.ndarray

    @classmethod
    def _from(cls, raw: Mapping[str, Any]) -> "Events":
        return cls(**{k: _column(v) for k, v in raw.items()})

    def __len__(self) -> int:
        return len(self.t)

    def __getitem__(self, name: str) -> np.ndarray:
        """A field by name (``events["t"]``), as a periodic orbit's events are read."""
        if name not in self.__dataclass_fields__:
            raise KeyError(name)
        return getattr(self, name)

    def table(self) -> Table:
        """The events as ``events.csv`` has them (same column names)."""
        n = self.x.shape[1]
        columns: Dict[str, Any] = {
            "time_s": self.t,
            "kind": self.kind,
            "contact": self.contact,
            "rel_velocity_m_s": self.speed_before,
            "rel_velocity_after_m_s": self.speed_after,
            "sequence_impacts": self.sequence_impacts,
        }
        columns.update(zip(_numbered("x", n, "_m"), self.x.T))
        columns.update(zip(_numbered("v", n, "_m_s"), self.v.T))
        return Table(columns)

    def to_pandas(self) -> "pandas.DataFrame":
        """The events as a pandas DataFrame with the columns of ``events.csv``."""
        return self.table().to_pandas()


class SimulationError(RuntimeError):
    """A run failed on the way (the event limit, a charge solver failure). ``result`` holds
    the periods before the failure; ``result.summary["error"]`` says why."""

    def __init__(self, message: str, result: "Simulation"):
        super().__init__(message)
        self.result = result


@dataclass(frozen=True, eq=False, repr=False)
class Simulation(Display):
    """One run of :func:`vibrotribo.simulate`: samples on the uniform grid of
    ``run.samples_per_period`` samples per excitation period (period boundaries included,
    the last one too), the events, and the summary.

    Attributes:
        t: sample times, s, shape (S,).
        x: positions x_i, m, shape (S, N).
        v: velocities, m/s, shape (S, N).
        y: base displacement, m, shape (S,).
        d: gaps d_k = δ_k − (x_{k+1} − x_k), m, shape (S, N−1).
        q: charge moved between the electrodes, C (None with ``mechanics_only``).
        i: current, A (None with ``mechanics_only``).
        v_load: load (terminal) voltage, V (None with ``mechanics_only``).
        c: transducer capacitance, F (None with ``mechanics_only``).
        voc: open-circuit voltage, V (None with ``mechanics_only``).
        vs: storage capacitor voltage, V (a rectifier load only, else None).
        events: every event of the run.
        summary: the keys and values of the command line's ``summary.json`` (average power
            in W after the transient, impacts, sticks, …; ``wall_time_s`` is this run's).
        config: the configuration that was run.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    y: np.ndarray
    d: np.ndarray
    events: Events
    summary: Dict[str, Any]
    config: Any
    q: Optional[np.ndarray] = None
    i: Optional[np.ndarray] = None
    v_load: Optional[np.ndarray] = None
    c: Optional[np.ndarray] = None
    voc: Optional[np.ndarray] = None
    vs: Optional[np.ndarray] = None

    @classmethod
    def _from(cls, raw: Dict[str, Any], config: Any) -> "Simulation":
        fields = {k: raw[k] for k in ("t", "x", "v", "y", "d")}
        for k in ("q", "i", "v_load", "c", "voc", "vs"):
            if k in raw:
                fields[k] = raw[k]
        return cls(events=Events._from(raw["events"]), summary=raw["summary"], config=config, **fields)

    @property
    def average_power_w(self) -> Optional[float]:
        """Average power after the transient, W (None without a harvester)."""
        return self.summary.get("average_power_w")

    @property
    def period_energy_j(self) -> Optional[np.ndarray]:
        """The energy delivered to the load in each excitation period, J, exact (the charge
        solver's integral of the power through every impact and sticking interval; None
        without a harvester). The samples of ``v_load * i`` miss the event instants, so
        integrating them undercounts a run with impacts between samples (chatter); these
        energies do not: ``period_energy_j[transient:].mean() / T`` is ``average_power_w``,
        with ``transient = summary["transient_periods"]`` and ``T = summary["excitation_period_s"]``."""
        e = self.summary.get("energy_in_each_period_j")
        return None if e is None else np.asarray(e, dtype=float)

    @property
    def period_power_w(self) -> Optional[np.ndarray]:
        """The average power of each excitation period, W: ``period_energy_j / T``."""
        e = self.period_energy_j
        return None if e is None else e / float(self.summary["excitation_period_s"])

    def table(self) -> Table:
        """The samples as ``trajectory.csv`` has them (same column names)."""
        n = self.x.shape[1]
        columns: Dict[str, Any] = {"time_s": self.t}
        columns.update(zip(_numbered("x", n, "_m"), self.x.T))
        columns.update(zip(_numbered("v", n, "_m_s"), self.v.T))
        if self.q is not None:
            columns.update(
                {"q_c": self.q, "i_a": self.i, "v_v": self.v_load, "c_f": self.c, "voc_v": self.voc}
            )
            if self.vs is not None:
                columns["vs_v"] = self.vs
        columns["y_m"] = self.y
        columns.update(zip(_numbered("d", n - 1, "_m"), self.d.T))
        return Table(columns)

    def to_pandas(self) -> "pandas.DataFrame":
        """The samples as a pandas DataFrame with the columns of ``trajectory.csv``."""
        return self.table().to_pandas()


def _equal_values(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and _same(a, b)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal_values(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_equal_values(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return a == b


@dataclass(frozen=True, eq=False, repr=False)
class Sweep(Display):
    """A one-parameter sweep of :func:`vibrotribo.sweep`, in the order the values were run
    (decreasing for ``continuation="down"``), as the command line writes it.

    Attributes:
        summary: ``summary.csv``: ``param``, ``average_power_w`` (W, NaN with
            ``mechanics_only``), ``impacts_per_period``, ``period`` (0 = non-periodic,
            −1 = the point failed), ``chatter``, ``sticking``, ``grazing``,
            ``impacts_per_period_1…``, ``error`` ("" if none).
        orbit: ``orbit.csv``: ``param``, ``period`` (n of the stroboscopic sample t = nT),
            ``x1_m … xN_m`` (m), one row per recorded period.
        impacts: ``impacts.csv``: ``param``, ``time_s`` (from the start of the point's run),
            ``contact`` (1-based), ``rel_velocity_m_s`` (closing speed, m/s).
        settings: the keys of ``sweep.json`` with its values (param, values, continuation,
            transient and recorded periods, tolerances, settling, the configuration's
            settings), less the shard.
    """

    summary: Table
    orbit: Table
    impacts: Table
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Sweep":
        return cls(Table(raw["summary"]), Table(raw["orbit"]), Table(raw["impacts"]), raw["settings"])

    @property
    def param(self) -> str:
        """The swept key."""
        return self.settings["param"]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sweep):
            return NotImplemented
        return (
            self.summary == other.summary
            and self.orbit == other.orbit
            and self.impacts == other.impacts
            and _equal_values(self.settings, other.settings)
        )

    __hash__ = None  # type: ignore[assignment]

    def to_pandas(self) -> "pandas.DataFrame":
        """The summary table as a pandas DataFrame."""
        return self.summary.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Map(Display):
    """A two-parameter map of :func:`vibrotribo.map`: ``summary`` is ``map.csv`` (``x``,
    ``y`` and the columns of a sweep's summary), y outer and x inner; ``settings`` the keys
    of ``map.json`` with its values but the shard, its axes as ``x``, ``x_values``, ``y``,
    ``y_values``."""

    summary: Table
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Map":
        return cls(Table(raw["summary"]), raw["settings"])

    def grid(self, column: str) -> np.ndarray:
        """``column`` as a 2-D array of shape (len(y_values), len(x_values))."""
        ny, nx = len(self.settings["y_values"]), len(self.settings["x_values"])
        return self.summary[column].reshape(ny, nx)

    def to_pandas(self) -> "pandas.DataFrame":
        """The map as a pandas DataFrame."""
        return self.summary.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class LoadSweep(Display):
    """Average power against the load resistance on one mechanical run
    (:func:`vibrotribo.load_sweep`), as ``vibrotribo load-sweep`` writes it.

    Attributes:
        points: ``load_sweep.csv``: ``load_resistance_ohm`` (Ω), ``average_power_w`` (W, after
            the transient), ``energy_per_period_j`` (J).
        optimum: the best load, refined by golden-section search: ``resistance_ohm``,
            ``average_power_w``, ``energy_per_period_j``.
        optimum_at_edge: whether the best grid point is at an end of the range (widen it).
        configured_load_ohm: the configuration's load resistance, Ω.
        configured_average_power_w: the average power at it, W.
        vq_cycle: ``vq_cycle.csv``: ``load_resistance_ohm``, ``time_s``, ``q_c`` (C), ``v_v``
            (V), ``i_a`` (A) over the last period, at the configured and the optimal load
            (empty with ``vq_points=None``).
        air_breakdown_last_period: the worst air-breakdown ratio over the last period at
            each of those loads.
    """

    points: Table
    optimum: Dict[str, float]
    optimum_at_edge: bool
    configured_load_ohm: float
    configured_average_power_w: float
    vq_cycle: Table
    air_breakdown_last_period: List[Dict[str, Any]]
    periods: int
    transient_periods: int

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "LoadSweep":
        return cls(**dict(raw, points=Table(raw["points"]), vq_cycle=Table(raw["vq_cycle"])))

    def to_pandas(self) -> "pandas.DataFrame":
        """The points as a pandas DataFrame."""
        return self.points.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Orbit(Display):
    """A periodic orbit of :func:`vibrotribo.periodic`, on the section t ≡ 0 (mod T).

    Attributes:
        period: period in excitation periods T.
        x, v: the state at t = 0 on the orbit: positions (m) and velocities (m/s).
        multipliers: Floquet multipliers (complex, largest modulus first), the eigenvalues
            of the monodromy matrix.
        stable: whether all multipliers lie inside the unit circle.
        spectral_radius: the largest modulus.
        unstable_dimension: multipliers outside the unit circle.
        impacts_per_period: impacts per excitation period, per contact.
        sticks: whether a contact sticks on the orbit.
        residual: scaled residual of the converged Newton iteration; ``residuals`` its history.
        duration_s: period·T, s.
        monodromy: the monodromy matrix Φ(PT), (2N, 2N), state order [x1…xN, v1…vN].
        events: the events along one period, a :class:`Table` with ``t`` (s), ``kind``,
            ``contact`` (1-based) and ``speed_before`` (m/s), read as a simulation's events
            are (``orbit.events.t``, ``orbit.events["kind"]``).
        average_power_w: the harvester's average power on the orbit, W (2 periods of the
            orbit to settle the charge, then 4 averaged, as ``vibrotribo periodic``; None with
            ``mechanics_only`` or a single mass).
        energy_per_period_j: the energy per excitation period there, J.
    """

    period: int
    x: np.ndarray
    v: np.ndarray
    multipliers: np.ndarray
    stable: bool
    spectral_radius: float
    unstable_dimension: int
    impacts_per_period: np.ndarray
    sticks: bool
    residual: float
    residuals: np.ndarray
    duration_s: float
    monodromy: np.ndarray
    events: Any
    average_power_w: Optional[float] = None
    energy_per_period_j: Optional[float] = None

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Orbit":
        return cls(**dict(raw, events=Table(raw["events"])))

    def to_pandas(self) -> "pandas.DataFrame":
        """The orbit as a one-row pandas DataFrame: period, stability, spectral radius,
        power and the state ``x1_m …``, ``v1_m_s …`` at t = 0."""
        row: Dict[str, Any] = {
            "period": self.period,
            "stable": self.stable,
            "spectral_radius": self.spectral_radius,
            "unstable_dimension": self.unstable_dimension,
            "sticks": self.sticks,
            "average_power_w": np.nan if self.average_power_w is None else self.average_power_w,
        }
        row.update(zip(_numbered("x", len(self.x), "_m"), self.x))
        row.update(zip(_numbered("v", len(self.v), "_m_s"), self.v))
        return _pandas().DataFrame([row])


@dataclass(frozen=True, eq=False, repr=False)
class Lyapunov(Display):
    """The Lyapunov spectrum of :func:`vibrotribo.lyapunov` (the numbers of ``lyapunov.json``).

    Attributes:
        exponents: the 2N exponents, 1/s, largest first; ``-inf`` for the directions a stuck
            contact or a chatter sequence removes.
        spread: the batch-means standard error of each, 1/s (0 for a ``-inf`` exponent).
        largest, largest_spread: the largest exponent and its spread, 1/s.
        sum: the sum of the exponents, 1/s (``-inf`` if any is).
        kaplan_yorke_dimension: the Kaplan–Yorke dimension.
        collapsed: number of ``-inf`` exponents.
        periods: excitation periods averaged over; time_s: their duration, s.
        skipped_periods: periods left out at non-differentiable points (grazing,
            simultaneous impacts).
        running_periods, running: the estimate after each batch (rows of ``running``).
    """

    exponents: np.ndarray
    spread: np.ndarray
    largest: float
    largest_spread: float
    sum: float
    kaplan_yorke_dimension: float
    collapsed: int
    periods: int
    time_s: float
    skipped_periods: int
    running_periods: np.ndarray
    running: np.ndarray

    def to_pandas(self) -> "pandas.DataFrame":
        """The running estimates as a pandas DataFrame: ``periods`` and one column
        ``lambda1_1_s …`` per exponent (1/s), a row per batch."""
        columns: Dict[str, Any] = {"periods": self.running_periods}
        columns.update(zip(_numbered("lambda", self.running.shape[1], "_1_s"), self.running.T))
        return _pandas().DataFrame(columns)


@dataclass(frozen=True, eq=False, repr=False)
class Branch(Display):
    """One branch of a continuation.

    Attributes:
        period: period of its orbits, in excitation periods.
        parent: (parent branch, index of the period doubling in its ``bifurcations``), or None.
        points: arrays along the branch: ``parameter``, ``x`` and ``v`` (P, N),
            ``multipliers`` (P, 2N) complex, ``stable``, ``sticks``, ``impacts_per_period``
            (P, contacts), ``arclength``, ``spectral_radius``, ``average_power_w`` (W, the
            harvester on each orbit as ``vibrotribo continue`` computes it; NaN with
            ``mechanics_only`` or where the charge solver failed), ``min_closing_speed_m_s``
            (the smallest closing speed of an impact on the orbit, m/s; NaN without impacts)
            and ``min_closing_contact`` (its contact, 1-based; 0 without impacts).
        bifurcations: located bifurcations in order along the branch, each a dict with
            ``kind`` (``fold``, ``branch_point``, ``period_doubling``, ``neimark_sacker``
            with ``angle``, ``grazing`` with ``contact``/``appears``, ``sticking`` with
            ``contact``/``onset``, ``sequence_change``), ``parameter``, ``precision``, the
            orbit's ``x``, ``v``, ``multipliers``, ``child`` (the doubled branch's index, or
            at a branch point the first branch switched onto) and ``other_child`` (at a
            branch point, the second one).
        end: why the branch ended: ``reason`` (``range_end``, ``max_points``,
            ``step_floor``, ``grazing``, ``cascade_depth``, ``unlocated`` with the
            ``between`` bracket of a multiplier near −1 that could not be located,
            ``switch_failed``, ``collapsed``, ``closed``, ``retraced`` (back on its own
            orbits going the other way), ``rejoined`` with the ``branch``
            it reached, ``runs_onto`` with the ``branch`` it ran onto past a change of
            sequence, ``stopped``) and its details.
    """

    period: int
    parent: Optional[tuple]
    points: Dict[str, np.ndarray]
    bifurcations: List[Dict[str, Any]]
    end: Dict[str, Any]

    @property
    def parameter(self) -> np.ndarray:
        """The parameter along the branch."""
        return self.points["parameter"]

    def table(self) -> Table:
        """The points as columns: ``parameter``, ``x1_m …``, ``v1_m_s …``, ``stable``,
        ``spectral_radius``, ``min_closing_speed_m_s``, ``sticks``, ``average_power_w``,
        ``arclength``."""
        p = self.points
        n = p["x"].shape[1] if p["x"].ndim == 2 else 0
        columns: Dict[str, Any] = {"parameter": p["parameter"]}
        columns.update(zip(_numbered("x", n, "_m"), p["x"].T))
        columns.update(zip(_numbered("v", n, "_m_s"), p["v"].T))
        for k in ("stable", "spectral_radius", "min_closing_speed_m_s", "sticks", "average_power_w", "arclength"):
            columns[k] = p[k]
        return Table(columns)

    def to_pandas(self) -> "pandas.DataFrame":
        """The points as a pandas DataFrame (the columns of :meth:`table`)."""
        return self.table().to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Continuation(Display):
    """The branches of :func:`vibrotribo.continue_`: the first, then the period-doubled ones
    in the order they were found."""

    parameter: str
    branches: List[Branch]

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Continuation":
        return cls(raw["parameter"], [Branch(**b) for b in raw["branches"]])

    @property
    def bifurcations(self) -> List[Dict[str, Any]]:
        """Every bifurcation of every branch, each with its ``branch`` index."""
        return [dict(b, branch=j) for j, br in enumerate(self.branches) for b in br.bifurcations]

    def to_pandas(self) -> "pandas.DataFrame":
        """Every point of every branch as one pandas DataFrame: ``branch`` (index),
        ``period`` and the columns of :meth:`Branch.table`."""
        pd = _pandas()
        frames = []
        for j, b in enumerate(self.branches):
            f = b.to_pandas()
            f.insert(0, "period", b.period)
            f.insert(0, "branch", j)
            frames.append(f)
        return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
