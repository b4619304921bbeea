"""The result of :func:`vibrotribo.curve`: a bifurcation curve in two configuration keys."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Dict, List, Optional

import numpy as np

from ._display import Display
from ._results import _pandas

if TYPE_CHECKING:
    import pandas


@dataclass(frozen=True, eq=False, repr=False)
class Curve(Display):
    """A fold, period-doubling, Neimark–Sacker or grazing curve in two keys.

    Attributes:
        kind: ``fold``, ``period_doubling``, ``neimark_sacker`` or ``grazing``.
        param: the first key (canonical: ``omega_ratio`` is ``excitation.omega_ratio``).
        param2: the second key (canonical).
        period: period of the orbits, in excitation periods.
        contact: grazing curves: the contact that grazes, 1-based (None otherwise).
        located: where the bifurcation was located on the branch at ``from2`` (value of
            ``param``), and ``located_precision`` the width of that bracket.
        points: arrays along the curve: ``parameter``, ``parameter2``, ``x`` and ``v``
            (P, N), ``multipliers`` (P, 2N) complex, ``condition`` (the bifurcation
            condition's value, zero to the tolerance), ``gap_minimum_m`` (grazing curves;
            NaN otherwise), ``impacts_per_period`` (P, contacts), ``arclength`` and
            ``average_power_w`` (W; NaN with ``mechanics_only``, for a single mass, or where
            the charge solver failed).
        codim2: the codimension-two points in order along the curve, each a dict with
            ``kind`` (``grazing``, ``sequence_change`` or ``meets_KIND``), ``contact``,
            ``parameter``, ``parameter2``, ``precision`` and ``multipliers``.
        end: why the curve ended: ``reason`` (``range_end``, ``max_points``,
            ``step_floor``, ``sequence_change``, ``degenerate``) and its details.
    """

    kind: str
    param: str
    param2: str
    period: int
    contact: Optional[int]
    located: float
    located_precision: float
    points: Dict[str, np.ndarray]
    codim2: List[Dict[str, Any]]
    end: Dict[str, Any]

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "Curve":
        return cls(**raw)

    @property
    def parameter(self) -> np.ndarray:
        """The first key along the curve."""
        return self.points["parameter"]

    @property
    def parameter2(self) -> np.ndarray:
        """The second key along the curve."""
        return self.points["parameter2"]

    def to_pandas(self) -> "pandas.DataFrame":
        """The points as a pandas DataFrame with the columns of ``curve.csv``: the two keys
        by name, ``period``, ``kind``, ``condition``, ``multiplier_K_re``/``_im``,
        ``x1_m …``, ``v1_m_s …``, ``impacts_per_period_K``, ``gap_minimum_m``,
        ``average_power_w``, ``arclength``."""
        p = self.points
        rows = len(p["parameter"])
        columns: Dict[str, Any] = {
            self.param: p["parameter"],
            self.param2: p["parameter2"],
            "period": np.full(rows, self.period),
            "kind": np.full(rows, self.kind),
            "condition": p["condition"],
        }
        m = p["multipliers"]
        for k in range(m.shape[1] if m.ndim == 2 else 0):
            columns[f"multiplier_{k + 1}_re"] = m[:, k].real
            columns[f"multiplier_{k + 1}_im"] = m[:, k].imag
        for name, unit in (("x", "_m"), ("v", "_m_s")):
            a = p[name]
            for k in range(a.shape[1] if a.ndim == 2 else 0):
                columns[f"{name}{k + 1}{unit}"] = a[:, k]
        imp = p["impacts_per_period"]
        for k in range(imp.shape[1] if imp.ndim == 2 else 0):
            columns[f"impacts_per_period_{k + 1}"] = imp[:, k]
        for name in ("gap_minimum_m", "average_power_w", "arclength"):
            columns[name] = p[name]
        return _pandas().DataFrame(columns)
