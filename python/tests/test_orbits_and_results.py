"""Periodic orbits and their continuation from Python, checked against direct simulation
(an orbit's state comes back after its period); result objects: dtypes, pandas, pickle."""

import pickle

import numpy as np
import pytest

import vibrotribo as vt


def come_back(config, x, v, period):
    """The state after `period` excitation periods of a direct run from (x, v) at t = 0."""
    c = config.replace(
        run__initial_positions=list(x), run__initial_velocities=list(v),
        run__periods=period, run__transient_periods=0, run__samples_per_period=4,
    )
    r = vt.simulate(c, mechanics_only=True)
    return r.x[-1], r.v[-1]


def test_periodic_orbit_is_a_fixed_point_of_the_flow():
    config = vt.Config()
    o = vt.periodic(config)
    assert o.period == 1 and o.stable
    assert o.multipliers.dtype == np.complex128 and o.multipliers.shape == (6,)
    assert o.spectral_radius == pytest.approx(np.abs(o.multipliers).max(), rel=1e-15)
    assert o.monodromy.shape == (6, 6)
    assert np.allclose(np.linalg.eigvals(o.monodromy)[np.argsort(-np.abs(np.linalg.eigvals(o.monodromy)))].__abs__(),
                       np.abs(o.multipliers), rtol=1e-9)
    x, v = come_back(config, o.x, o.v, o.period)
    assert np.allclose(x, o.x, atol=1e-12, rtol=0) and np.allclose(v, o.v, atol=1e-10, rtol=0)
    assert o.impacts_per_period.shape == (2,) and o.impacts_per_period.sum() >= 1
    # The same orbit from a guess.
    again = vt.periodic(config, guess=(o.x + 1e-5, o.v), period=1)
    assert np.allclose(again.x, o.x, atol=1e-12)


def test_continuation_points_are_periodic_orbits():
    config = vt.Config()
    c = vt.continue_(config, "omega_ratio", 0.70, 0.74, max_points=40)
    assert c.parameter == "omega_ratio" and len(c.branches) >= 1
    b = c.branches[0]
    p = b.points
    n = len(p["parameter"])
    assert n >= 2 and p["x"].shape == (n, 3) and p["multipliers"].shape == (n, 6)
    assert p["multipliers"].dtype == np.complex128 and p["stable"].dtype == np.bool_
    assert b.end["reason"] in {"range_end", "max_points", "step_floor", "grazing", "cascade_depth",
                               "switch_failed", "collapsed"}
    for j in (0, n // 2, n - 1):
        w = float(p["parameter"][j])
        x, v = come_back(config.replace(omega_ratio=w), p["x"][j], p["v"][j], b.period)
        assert np.allclose(x, p["x"][j], atol=1e-9, rtol=0), (w, x, p["x"][j])


def test_results_pickle_and_convert():
    pd = pytest.importorskip("pandas")
    r = vt.simulate(vt.Config(run__periods=5, run__transient_periods=1))
    df = r.to_pandas()
    assert list(df.columns) == r.table().columns and len(df) == len(r.t)
    assert list(r.events.to_pandas().columns)[:3] == ["time_s", "kind", "contact"]
    s = vt.sweep(None, "omega_ratio", [0.6, 0.7], transient=5, recorded=4)
    assert pickle.loads(pickle.dumps(s)) == s
    assert isinstance(s.to_pandas(), pd.DataFrame) and s.summary.param.tolist() == [0.6, 0.7]
    back = pickle.loads(pickle.dumps(r))
    assert np.array_equal(back.x, r.x) and back.summary == r.summary and back.config == r.config


def test_a_failed_run_raises_with_its_partial_result():
    with pytest.raises(vt.SimulationError, match="simulation stopped after") as e:
        vt.simulate(vt.Config(options__max_events_per_period=2))
    assert e.value.result.summary["error"] == str(e.value)
    assert e.value.result.summary["periods"] < e.value.result.summary["periods_requested"]
