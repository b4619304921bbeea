"""Results read the same way everywhere: grids and log-spaced values are numpy arrays with
exact end points, a result's repr is short, every result converts to pandas, events are
read alike on runs and orbits; the exact per-period energies integrate to the summary's
average power; a map over initial conditions skips interpenetrating starts."""

import numpy as np
import pytest

import vibrotribo as vt
from conftest import CONFIGS


def test_grid_and_log_spaced_are_arrays_with_exact_ends():
    r = vt.log_spaced(1e3, 1e13, 3)
    assert isinstance(r, np.ndarray) and r[0] == 1e3 and r[-1] == 1e13
    assert r[1] == pytest.approx(1e8, rel=1e-14)
    g = vt.grid(0.3, 1.0, 8)
    assert isinstance(g, np.ndarray) and g[0] == 0.3 and g[-1] == 1.0


def test_reprs_are_short():
    run = vt.simulate(vt.Config(run__periods=20))
    assert len(repr(run)) < 1000, repr(run)
    assert "<table>" in run._repr_html_()
    sw = vt.sweep(None, "omega_ratio", vt.grid(0.6, 0.7, 2), transient=10, recorded=5)
    assert len(repr(sw)) < 1000


def test_every_result_converts_to_pandas():
    pd = pytest.importorskip("pandas")
    o = vt.periodic(vt.Config())
    assert isinstance(o.to_pandas(), pd.DataFrame) and len(o.to_pandas()) == 1
    c = vt.continue_(vt.Config(), "omega_ratio", 0.7, 0.72, mechanics_only=True)
    df = c.to_pandas()
    assert len(df) == sum(len(b.parameter) for b in c.branches) and "spectral_radius" in df
    ly = vt.lyapunov(vt.Config(), periods=40, transient=20, batches=4)
    assert len(ly.to_pandas()) == len(ly.running_periods)


def test_events_read_alike_on_runs_and_orbits():
    run = vt.simulate(vt.Config(run__periods=10), samples=False)
    o = vt.periodic(vt.Config(), mechanics_only=True)
    for events in (run.events, o.events):
        assert isinstance(events.t, np.ndarray) and isinstance(events["kind"], np.ndarray)
        assert events["contact"].dtype == np.int64


def test_period_energies_give_the_average_power_in_the_chatter_case():
    run = vt.simulate(vt.Config(CONFIGS / "chatter.toml"), samples=False)
    s = run.summary
    e = run.period_energy_j
    transient = s["transient_periods"]
    # The summary's average power is the energy after the transient over its duration.
    expected = e[transient:].sum() / ((len(e) - transient) * s["excitation_period_s"])
    assert expected == pytest.approx(run.average_power_w, rel=1e-12)


def test_period_energies_agree_with_a_fine_quadrature_of_the_samples():
    # A run without chatter sampled finely: the trapezoid of v·i over a period approaches the
    # exact energy of that period (the independent check of the energies).
    run = vt.simulate(vt.Config(run__periods=12, run__samples_per_period=20000))
    T = run.summary["excitation_period_s"]
    k = 10
    m = (run.t >= k * T - 1e-15) & (run.t <= (k + 1) * T + 1e-15)
    p = run.v_load[m] * run.i[m]
    quad = float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(run.t[m])))
    assert quad == pytest.approx(run.period_energy_j[k], rel=2e-3)


def test_a_map_over_initial_conditions_skips_interpenetrating_starts():
    m = vt.map(vt.Config(), "run.initial_positions[0]", [-0.03, 0.0], "run.initial_velocities[0]", [0.0],
               transient=10, recorded=5, mechanics_only=True)
    err = m.summary["error"]
    assert err[0] != "" and err[1] == "", list(err)
    assert m.summary["period"][0] == -1
