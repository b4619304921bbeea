"""Result objects of the studies beside sweeps and orbits: the chirp experiment, basins of
attraction, the attractor census, the optimal mass ratio, the frequency responses and the
ngspice export. Columns
carry the names of the command line's CSV files; numbers are float64 (NaN where the file
leaves a cell empty), counts int64 (−1 where the file leaves a cell empty), text str."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Optional

import numpy as np

if TYPE_CHECKING:  # pandas is optional: only to_pandas() needs it
    import pandas

from ._display import Display
from ._results import Table

__all__ = ["Chirp", "Basins", "Attractors", "MassRatioOptimum", "Response", "BandResponse", "SpiceExport"]


@dataclass(frozen=True, eq=False, repr=False)
class Chirp(Display):
    """The frequency-sweep experiment of :func:`vibrotribo.chirp` (``vibrotribo chirp``).

    Attributes:
        response: ``response.csv``: ``direction`` (``up``/``down``), ``cycle`` (from 1),
            ``time_s`` (middle of the cycle, s), ``omega_ratio``, ``frequency_hz`` (Hz),
            ``amplitude1_m …`` (each mass relative to the base, (max − min)/2 over the cycle,
            m), ``impacts``, and ``power_w`` (W; with a harvester).
        up, down: per direction what ``chirp.json`` records: ``f_start_hz``,
            ``f_end_hz_requested``, ``run_duration_s``, ``periods``, ``cycles``,
            ``impacts``, ``complete``, ``failure``, ``jump`` (``omega_ratio``,
            ``frequency_hz``, ``cycle``, ``mass`` 1-based, ``size_m``, ``relative``; None with
            too few cycles). None for a direction that did not run.
        settings: the keys of ``chirp.json`` but the runs (``up``, ``down``,
            ``hysteresis``), ``complete`` and the wall time: the options and the
            configuration's settings.
        complete: whether both chirps ran to the end.
    """

    response: Table
    up: Optional[Dict[str, Any]]
    down: Optional[Dict[str, Any]]
    settings: Dict[str, Any] = field(default_factory=dict)
    complete: bool = True

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Chirp":
        return cls(Table(raw["response"]), raw["up"], raw["down"], raw["settings"], raw["complete"])

    @property
    def hysteresis(self) -> Optional[Dict[str, float]]:
        """The jumps up and down and the width between them (Ω), or None if either chirp has
        no jump: ``up_jump_omega_ratio``, ``down_jump_omega_ratio``, ``width``."""
        u = (self.up or {}).get("jump")
        d = (self.down or {}).get("jump")
        if not (u and d):
            return None
        return {
            "up_jump_omega_ratio": u["omega_ratio"],
            "down_jump_omega_ratio": d["omega_ratio"],
            "width": u["omega_ratio"] - d["omega_ratio"],
        }

    def direction(self, which: str) -> Table:
        """The rows of one direction (``"up"`` or ``"down"``)."""
        keep = self.response["direction"] == which
        return Table({k: v[keep] for k, v in self.response.items()})

    def to_pandas(self) -> "pandas.DataFrame":
        """The response as a pandas DataFrame."""
        return self.response.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Basins(Display):
    """Basins of attraction of :func:`vibrotribo.basins` (``vibrotribo basins``).

    Attributes:
        basins: ``basins.csv``: ``x``, ``y`` (the start), ``attractor`` (1-based; −1 for a
            start that did not run, e.g. interpenetrating masses), ``period`` (0:
            non-periodic), ``impacts_per_period``, ``average_power_w`` (W); y outer, x inner.
        attractors: ``attractors.csv``: ``attractor``, ``period``, ``starts``,
            ``fraction`` and ``fraction_se`` (the basin's share of the starts that ran and
            its standard error), ``impacts_per_period``, ``average_power_w``,
            ``power_se_w``, and a point of its section ``x1_m … v1_m_s …``.
        starts: the starts with their ``error`` ("" if none), as ``starts.csv`` without the
            section fingerprints.
        settings: the keys of ``basins.json`` with its values but the shard, its axes as
            ``x``, ``x_values``, ``y``, ``y_values``: periods, tolerances and the
            configuration's settings.
    """

    basins: Table
    attractors: Table
    starts: Table
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Basins":
        return cls(Table(raw["basins"]), Table(raw["attractors"]), Table(raw["starts"]), raw["settings"])

    def grid(self, column: str = "attractor") -> np.ndarray:
        """``column`` of ``basins`` as a 2-D array of shape (len(y_values), len(x_values))."""
        ny, nx = len(self.settings["y_values"]), len(self.settings["x_values"])
        return self.basins[column].reshape(ny, nx)

    def to_pandas(self) -> "pandas.DataFrame":
        """The basins table as a pandas DataFrame."""
        return self.basins.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Attractors(Display):
    """The attractor census of :func:`vibrotribo.attractors` (``vibrotribo attractors``).

    Attributes:
        attractors: ``attractors.csv``: ``param``, ``attractor`` (its identity across
            values, 1-based), ``period``, ``starts``, ``fraction``, ``fraction_se``,
            ``impacts_per_period``, ``average_power_w``, ``power_se_w``, and a point of its
            section ``x1_m … v1_m_s …``.
        expected_power: ``expected_power.csv``: ``param``, ``expected_power_w`` and
            ``expected_power_se_w`` (the mean power of a random start and its standard
            error, W), ``attractors``, ``starts`` (classified), ``failed``, ``error``.
        settings: the keys of ``attractors.json`` with its values but the progress
            (``complete``, ``done``): values, samples, seed, periods, tolerances and the
            configuration's settings.
    """

    attractors: Table
    expected_power: Table
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Attractors":
        return cls(Table(raw["attractors"]), Table(raw["expected_power"]), raw["settings"])

    def to_pandas(self) -> "pandas.DataFrame":
        """The attractors table as a pandas DataFrame."""
        return self.attractors.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class Response(Display):
    """The frequency response of :func:`vibrotribo.response` (``vibrotribo response``).

    Attributes:
        response: ``response.csv``: ``param`` (the value, increasing), then each sweep's
            column beside the other's: ``power_up_w``, ``power_down_w`` (average power, W),
            ``power_se_up_w``, ``power_se_down_w`` (its batch-means standard error, W),
            ``period_up``, ``period_down`` (excitation periods, 0: not periodic),
            ``impacts_per_period_up``, ``impacts_per_period_down``, ``motion_up``,
            ``motion_down``, ``error_up``, ``error_down``.
        branches: ``branches.csv`` (empty without ``branches=True``): ``branch``, ``period``,
            ``param``, ``stable``, ``power_w`` (W), ``max_abs_multiplier``,
            ``impacts_per_period``, a row per point along each branch.
        summary: what ``response.json`` records of the result: ``bandwidth`` (the envelope's
            ``peak_at``, ``peak_power_w``, ``lower``, ``upper``, ``width``; None edges run
            past the range), ``up`` and ``down`` (``done``, ``failed``, ``bandwidth``),
            ``seeding`` and ``branches`` (each ``branch``, ``seed_sweep``, ``seed_at``,
            ``towards``, ``period``, ``points``, ``stable_points``, ``bifurcations``, ``end``,
            ``end_at``, ``bandwidth``) with ``branches=True``, ``complete``.
        settings: the keys of ``response.json`` but the summary (the result's
            ``summary``) and the wall time: the key, values, periods, settling and the
            configuration's settings.
    """

    response: Table
    branches: Table
    summary: Dict[str, Any]
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Response":
        return cls(Table(raw["response"]), Table(raw["branches"]), raw["summary"], raw["settings"])

    @property
    def bandwidth(self) -> Optional[Dict[str, Any]]:
        """The peak and half-power band of the envelope of both sweeps and the stable branch
        points (``peak_at``, ``peak_power_w``, ``lower``, ``upper``, ``width``), or None."""
        return self.summary["bandwidth"]

    def to_pandas(self) -> "pandas.DataFrame":
        """The response table as a pandas DataFrame."""
        return self.response.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class BandResponse(Display):
    """The response to band-limited random input of :func:`vibrotribo.band_response`
    (``vibrotribo band-response``).

    Attributes:
        response: ``response.csv``: ``centre_hz``, ``f_low_hz``, ``f_high_hz`` (Hz),
            ``power_w`` (the mean over the seeds, W), ``power_se_w`` (its standard error,
            W), ``runs`` (seeds with a power), ``power_min_w``, ``power_max_w``.
        seeds: ``seeds.csv``: ``centre_hz``, ``seed``, ``power_w``, ``power_se_w`` (the
            run's batch-means standard error), ``error``, a row per run.
        summary: what ``band_response.json`` records of the result: ``centres_hz``,
            ``width_hz``, ``rms_acceleration``, ``seeds``, ``bandwidth`` (Hz), ``failed``,
            ``complete``.
        settings: the keys of ``band_response.json`` but the summary (the result's
            ``summary``), the centres' range and the wall time: the periods, settling and
            the configuration's settings.
    """

    response: Table
    seeds: Table
    summary: Dict[str, Any]
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "BandResponse":
        return cls(Table(raw["response"]), Table(raw["seeds"]), raw["summary"], raw["settings"])

    @property
    def bandwidth(self) -> Optional[Dict[str, Any]]:
        """The peak and half-power band of the mean power against the centre frequency, Hz,
        or None."""
        return self.summary["bandwidth"]

    def to_pandas(self) -> "pandas.DataFrame":
        """The response table as a pandas DataFrame."""
        return self.response.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class MassRatioOptimum(Display):
    """The optimal mass ratio R_mo(Ω) of :func:`vibrotribo.optimize_mass_ratio`
    (``vibrotribo optimize-mass-ratio``).

    Attributes:
        power_grid: ``power_grid.csv``: ``omega_ratio``, ``mass_ratio``,
            ``average_power_w`` (W), ``impacts_per_period``, ``period``, ``error``; Ω outer.
        optimum: ``optimum.csv``: ``omega_ratio``, ``optimal_mass_ratio`` (the best R_m
            refined by a parabola), ``average_power_w`` there (W), ``at_edge``,
            ``paper_fit`` (the paper's fit at that Ω).
        fit: the quadratic R_mo = aΩ² + bΩ + c through the optima (``a``, ``b``, ``c``,
            ``r_squared``, ``rms_residual``), None with fewer than three optima.
        paper_fit: the paper's ``a``, ``b``, ``c``.
        settings: the grids, periods and the configuration's settings.
    """

    power_grid: Table
    optimum: Table
    fit: Optional[Dict[str, Any]]
    paper_fit: Dict[str, float]
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "MassRatioOptimum":
        return cls(Table(raw["power_grid"]), Table(raw["optimum"]), raw["fit"], raw["paper_fit"], raw["settings"])

    def power(self) -> np.ndarray:
        """The average power as a 2-D array of shape (Ω values, R_m values), W."""
        n_w = len(self.settings["omega_values"])
        return self.power_grid["average_power_w"].reshape(n_w, -1)

    def to_pandas(self) -> "pandas.DataFrame":
        """The optima as a pandas DataFrame."""
        return self.optimum.to_pandas()


@dataclass(frozen=True, eq=False, repr=False)
class SpiceExport(Display):
    """An ngspice netlist of a run's harvester (:func:`vibrotribo.export_spice`), the text
    ``vibrotribo export-spice`` writes.

    Attributes:
        netlist: the deck (run it with ``ngspice -b``; it writes ``data_file``: time, charge
            in nC, energy in nJ, voltage).
        data_file: the file name the deck's ``wrdata`` writes.
        from_period, periods: the excitation periods exported.
        window_s: their start and end in the run's time, s (the deck starts at 0).
        pwl_times_s: the breakpoints of the gap sources, s (from 0).
        pwl_gaps_m: the gaps there, m, shape (breakpoints, contacts).
        energy_j, ngspice_energy_j: the energy delivered over the window by vibrotribo's
            charge solver and by ngspice, J (with ``check=True``; else None).
    """

    netlist: str
    data_file: str
    from_period: int
    periods: int
    window_s: tuple
    pwl_times_s: np.ndarray
    pwl_gaps_m: np.ndarray
    energy_j: Optional[float] = None
    ngspice_energy_j: Optional[float] = None
    ngspice_s: Optional[float] = None

    def write(self, path: Any) -> None:
        """Writes the netlist to ``path``."""
        with open(path, "w") as f:
            f.write(self.netlist)

    def to_pandas(self) -> "pandas.DataFrame":
        """The gap waveforms as a pandas DataFrame: ``time_s``, ``d1_m …``."""
        from ._results import _pandas

        columns: Dict[str, Any] = {"time_s": self.pwl_times_s}
        for k in range(self.pwl_gaps_m.shape[1]):
            columns[f"d{k + 1}_m"] = self.pwl_gaps_m[:, k]
        return _pandas().DataFrame(columns)
