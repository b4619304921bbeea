"""The result of :func:`vibrotribo.bifmap`: a device's bifurcation curves in two
configuration keys over its power map."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List

from ._display import Display
from ._results import Map, Table


@dataclass(frozen=True, eq=False, repr=False)
class BifurcationMap(Display):
    """Fold, period-doubling, Neimark–Sacker and grazing curves in two keys over the power
    map, as ``vibrotribo bifmap`` writes them.

    Attributes:
        x: the first key (canonical: ``omega_ratio`` is ``excitation.omega_ratio``).
        y: the second key (canonical).
        curves: ``curves.csv``: one row per point of every curve: ``curve`` (its index),
            the two keys by name, ``kind``, ``period``, ``contact`` (grazing, 1-based; −1
            otherwise), ``condition``, ``gap_minimum_m``, ``arclength`` (signed, zero at the
            seed), ``max_abs_multiplier``, ``multiplier_K_re``/``_im``, ``x1_m …``,
            ``v1_m_s …``, ``impacts_per_period_K``.
        codim2: ``codim2.csv``: the codimension-two points: ``curve``, ``kind``, the two
            keys, ``precision``, ``contact``, ``max_abs_multiplier``.
        located: ``located.csv``: the bifurcations located on the seed branches: ``seed``,
            the two keys, ``kind``, ``period``, ``contact``, ``curve`` (the curve it lies on;
            −1 where it was not followed).
        power: the power map (:class:`Map`; its ``summary`` is ``map.csv``, the points of
            :func:`vibrotribo.map` with the same settings).
        curve_info: per curve (as ``bifmap.json``): ``curve``, ``kind``, ``period``,
            ``contact``, ``seed_y``, ``located_x``, ``points``, ``ends`` (towards the first
            and the last y value: a dict with ``reason`` — ``curve``, ``left_map``,
            ``stopped``, ``no_start`` — and its details, or None where the seed is that end),
            ``found_again``.
        seeds: per seed branch: ``y``, ``x_start``, ``branches``, ``points``, ``error``.
        untraced: located bifurcations not followed (beyond ``max_curves``).
        settings: the settings of the power map and the seed values.
    """

    x: str
    y: str
    curves: Table
    codim2: Table
    located: Table
    power: Map
    curve_info: List[Dict[str, Any]]
    seeds: List[Dict[str, Any]]
    untraced: int
    settings: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from(cls, raw: Dict[str, Any]) -> "BifurcationMap":
        return cls(
            x=raw["x"],
            y=raw["y"],
            curves=Table(raw["curve_points"]),
            codim2=Table(raw["codim2"]),
            located=Table(raw["located"]),
            power=Map(Table(raw["map"]), raw["settings"]),
            curve_info=raw["curves"],
            seeds=raw["seeds"],
            untraced=raw["untraced"],
            settings=raw["settings"],
        )
