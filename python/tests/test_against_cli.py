"""The Python results equal the command line's files for the same configuration, bit for bit
in the numbers: samples, events, summary of `simulate`; the tables of `sweep` (parallel and
continued), `map`, `load_sweep` and `lyapunov`. Also the dtypes and shapes of every array."""

import json
import math

import numpy as np
import pytest

import vibrotribo as vt
from conftest import CONFIGS, assert_bits, compare_tables, numbers, read_csv, read_json, run_cli

# (name, command-line arguments, the same configuration for Python)
RUNS = [
    ("default", [], lambda: vt.Config()),
    ("chatter", [CONFIGS / "chatter.toml"], lambda: vt.Config(CONFIGS / "chatter.toml")),
    (
        "rectifier",
        ["--set", "harvester.load=rectifier", "--set", "run.periods=20", "--set", "run.transient_periods=10"],
        lambda: vt.Config(
            **{"harvester.load": "rectifier", "run.periods": 20, "run.transient_periods": 10}
        ),
    ),
    (
        "mechanics-4-masses",
        [
            "--set", "oscillator.masses=[0.05,0.1,0.08,0.05]",
            "--set", "run.periods=30",
            "--set", "excitation.omega_ratio=0.8",
            "--mechanics-only",
        ],
        lambda: vt.Config(
            {"oscillator": {"masses": [0.05, 0.1, 0.08, 0.05]}, "run": {"periods": 30}},
            omega_ratio=0.8,
        ),
    ),
]


def without_wall_time(summary):
    return {k: v for k, v in summary.items() if k != "wall_time_s"}


def same_json(got, expected, path="summary"):
    """Equal JSON values; floats compared bit for bit."""
    if isinstance(expected, dict):
        assert isinstance(got, dict) and list(got) == list(expected), f"{path}: keys {list(got)} != {list(expected)}"
        for k in expected:
            same_json(got[k], expected[k], f"{path}.{k}")
    elif isinstance(expected, list):
        assert isinstance(got, list) and len(got) == len(expected), f"{path}: lengths differ"
        for j, (a, b) in enumerate(zip(got, expected)):
            same_json(a, b, f"{path}[{j}]")
    elif isinstance(expected, float):
        assert isinstance(got, float) and (got == expected or (math.isnan(got) and math.isnan(expected))), (
            f"{path}: {got!r} != {expected!r}"
        )
        assert math.copysign(1, got) == math.copysign(1, expected), f"{path}: sign of {got!r}"
    else:
        assert got == expected and type(got) is type(expected), f"{path}: {got!r} != {expected!r}"


@pytest.mark.parametrize("name,args,config", RUNS, ids=[r[0] for r in RUNS])
def test_simulate_equals_the_files(cli, tmp_path, name, args, config):
    mechanics_only = "--mechanics-only" in args
    run_cli(cli, "simulate", *args, "--out", tmp_path)
    r = vt.simulate(config(), mechanics_only=mechanics_only)
    n = r.x.shape[1]

    header, cols = read_csv(tmp_path / "trajectory.csv")
    table = r.table()
    assert table.columns == header
    for name_ in header:
        assert_bits(table[name_], numbers(cols[name_]), f"trajectory.csv {name_}")
    s = len(cols["time_s"])
    assert r.t.shape == (s,) and r.x.shape == (s, n) and r.v.shape == (s, n)
    assert r.y.shape == (s,) and r.d.shape == (s, n - 1)
    for a in (r.t, r.x, r.v, r.y, r.d):
        assert a.dtype == np.float64
    if mechanics_only:
        assert r.q is None and r.i is None and r.vs is None
    else:
        for a in (r.q, r.i, r.v_load, r.c, r.voc):
            assert a.dtype == np.float64 and a.shape == (s,)
        assert (r.vs is not None) == (name == "rectifier")

    header, cols = read_csv(tmp_path / "events.csv")
    events = r.events.table()
    assert events.columns == header
    assert list(r.events.kind) == cols["kind"]
    for name_ in header:
        if name_ != "kind":
            assert_bits(events[name_], numbers(cols[name_]), f"events.csv {name_}")
    m = len(cols["time_s"])
    assert r.events.x.shape == (m, n) and r.events.contact.dtype == np.int64
    assert r.events.kind.dtype.kind == "U"

    same_json(without_wall_time(r.summary), without_wall_time(read_json(tmp_path / "summary.json")))
    assert isinstance(r.summary["wall_time_s"], float)


SWEEPS = [
    (
        "parallel",
        [CONFIGS / "chatter.toml", "--param", "omega_ratio", "--from", "0.3", "--to", "1.0",
         "--steps", "17", "--transient", "60", "--recorded", "24"],
        lambda: (vt.Config(CONFIGS / "chatter.toml"), "omega_ratio", vt.grid(0.3, 1.0, 17),
                 dict(transient=60, recorded=24, threads=2)),
    ),
    (
        "down-mechanics",
        ["--param", "mass_ratio", "--from", "1.5", "--to", "3", "--steps", "9", "--continuation",
         "down", "--mechanics-only", "--transient", "40", "--recorded", "20"],
        lambda: (vt.Config(), "mass_ratio", vt.grid(1.5, 3.0, 9),
                 dict(continuation="down", mechanics_only=True, transient=40, recorded=20)),
    ),
    (
        "failing-points",
        [CONFIGS / "chatter.toml", "--param", "omega_ratio", "--from", "0.3", "--to", "1.0",
         "--steps", "8", "--transient", "20", "--recorded", "10",
         "--set", "options.max_events_per_period=20"],
        lambda: (vt.Config(CONFIGS / "chatter.toml", **{"options.max_events_per_period": 20}),
                 "omega_ratio", vt.grid(0.3, 1.0, 8), dict(transient=20, recorded=10, threads=1)),
    ),
]


@pytest.mark.parametrize("name,args,setup", SWEEPS, ids=[s[0] for s in SWEEPS])
def test_sweep_equals_the_files(cli, tmp_path, name, args, setup):
    run_cli(cli, "sweep", *args, "--out", tmp_path)
    config, param, values, kwargs = setup()
    r = vt.sweep(config, param, values, **kwargs)
    compare_tables(
        [r.summary, r.orbit, r.impacts], tmp_path, ["summary.csv", "orbit.csv", "impacts.csv"]
    )
    settings = read_json(tmp_path / "sweep.json")
    for key in ("param", "values", "continuation", "transient_periods", "recorded_periods",
                "period_tolerance", "max_period_detected", "mechanics_only", "settings"):
        assert r.settings[key] == settings[key], key
    # How the points settled: the same keys, present or absent alike.
    for key in ("settle", "settle_cap_periods", "settle_block_periods", "settle_newton"):
        assert r.settings.get(key) == settings.get(key), key
    assert r.summary.rows == len(values)
    assert r.summary["period"].dtype == np.int64 and r.summary["chatter"].dtype == np.bool_
    if name == "failing-points":
        assert (r.summary["period"] == -1).any() and (r.summary["error"] != "").any()


def test_map_equals_the_file(cli, tmp_path):
    run_cli(
        cli, "map", "--x", "omega_ratio", "--x-from", "0.6", "--x-to", "0.8", "--x-steps", "3",
        "--y", "gap_ratio", "--y-from", "1", "--y-to", "1.5", "--y-steps", "2",
        "--transient", "30", "--recorded", "12", "--out", tmp_path,
    )
    r = vt.map(vt.Config(), "omega_ratio", vt.grid(0.6, 0.8, 3), "gap_ratio", vt.grid(1, 1.5, 2),
               transient=30, recorded=12)
    compare_tables([r.summary], tmp_path, ["map.csv"])
    assert r.grid("average_power_w").shape == (2, 3)


def test_thread_count_does_not_change_a_sweep():
    values = vt.grid(0.55, 0.85, 7)
    one = vt.sweep(None, "omega_ratio", values, transient=30, recorded=12, threads=1)
    two = vt.sweep(None, "omega_ratio", values, transient=30, recorded=12, threads=2)
    assert one == two


def test_load_sweep_equals_the_files(cli, tmp_path):
    run_cli(cli, "load-sweep", "--steps", "9", "--vq-points", "60", "--set", "run.periods=30",
            "--set", "run.transient_periods=10", "--out", tmp_path)
    r = vt.load_sweep(vt.Config(run__periods=30, run__transient_periods=10), steps=9, vq_points=60)
    compare_tables([r.points, r.vq_cycle], tmp_path, ["load_sweep.csv", "vq_cycle.csv"])
    expected = read_json(tmp_path / "load_sweep.json")
    same_json(r.optimum, expected["optimum"], "optimum")
    for key in ("optimum_at_edge", "configured_load_ohm", "configured_average_power_w",
                "air_breakdown_last_period", "periods", "transient_periods"):
        same_json(getattr(r, key), expected[key], key)


@pytest.mark.parametrize("sets", [[], ["oscillator.masses=[0.05,0.15,0.05]", "oscillator.gaps=[0.005,0.005]",
                                       "omega_ratio=0.6"]])
def test_lyapunov_equals_the_file(cli, tmp_path, sets):
    args = [a for s in sets for a in ("--set", s)]
    run_cli(cli, "lyapunov", *args, "--periods", "200", "--transient", "50", "--seed", "3", "--out", tmp_path)
    expected = read_json(tmp_path / "lyapunov.json")
    overrides = {s.split("=")[0]: json.loads(s.split("=")[1]) for s in sets}
    r = vt.lyapunov(vt.Config(**{k: v for k, v in overrides.items()}), periods=200, transient=50, seed=3)
    # lyapunov.json writes -inf as null.
    want = [float("-inf") if e is None else e for e in expected["exponents"]]
    assert r.exponents.tolist() == want
    assert r.periods == expected["periods"] == 200
    assert r.collapsed == expected["collapsed"]
    assert r.exponents.shape == (6,) and r.spread.shape == (6,)
    assert r.largest == r.exponents[0]


def test_lyapunov_rejects_bad_input():
    with pytest.raises(ValueError, match="periods"):
        vt.lyapunov(None, periods=0)
    with pytest.raises(ValueError, match="batches"):
        vt.lyapunov(None, periods=10, batches=1)


IMPACT = CONFIGS / "impact_oscillator.toml"


def test_sweep_with_a_stop_equals_the_files(cli, tmp_path):
    """A single mass below a rigid stop: contacts N - 1 = 0 between masses, N + 1 = 2 with
    the stops; the tables have a column per contact and equal the command line's files."""
    run_cli(cli, "sweep", IMPACT, "--param", "omega_ratio", "--from", "2.4", "--to", "2.8",
            "--steps", "5", "--mechanics-only", "--transient", "100", "--recorded", "16",
            "--out", tmp_path)
    r = vt.sweep(vt.Config(IMPACT), "omega_ratio", vt.grid(2.4, 2.8, 5), mechanics_only=True,
                 transient=100, recorded=16)
    compare_tables(
        [r.summary, r.orbit, r.impacts], tmp_path, ["summary.csv", "orbit.csv", "impacts.csv"]
    )
    assert "impacts_per_period_2" in r.summary.columns
    # The stop is above the mass: every impact is on the upper stop, contact N + 1 = 2.
    assert len(r.impacts["contact"]) > 0 and (r.impacts["contact"] == 2).all()


def test_map_with_a_stop_equals_the_file(cli, tmp_path):
    run_cli(
        cli, "map", IMPACT, "--x", "omega_ratio", "--x-from", "2.4", "--x-to", "2.8", "--x-steps", "3",
        "--y", "amplitude", "--y-from", "0.008", "--y-to", "0.012", "--y-steps", "2",
        "--mechanics-only", "--transient", "100", "--recorded", "16", "--out", tmp_path,
    )
    r = vt.map(vt.Config(IMPACT), "omega_ratio", vt.grid(2.4, 2.8, 3), "amplitude",
               vt.grid(0.008, 0.012, 2), mechanics_only=True, transient=100, recorded=16)
    compare_tables([r.summary], tmp_path, ["map.csv"])
    assert r.summary.rows == 6


def test_mass_ratio_on_one_mass_is_an_error():
    with pytest.raises(ValueError, match="mass_ratio needs at least 2"):
        vt.sweep(vt.Config(IMPACT), "mass_ratio", [1.5, 2.0], mechanics_only=True)


def test_an_integer_key_can_be_swept():
    config = vt.Config({
        "excitation": {"kind": "random", "rms_acceleration": 5.0, "f_low_hz": 3.0, "f_high_hz": 9.0},
        "run": {"periods": 4, "transient_periods": 2},
    })
    r = vt.sweep(config, "excitation.seed", [0, 1, 2], mechanics_only=True, threads=1)
    assert list(r.summary["error"]) == ["", "", ""]
    one = vt.sweep(config.replace(**{"excitation.seed": 1}), "restitution", [0.6],
                   mechanics_only=True, threads=1)
    assert_bits(r.orbit["x1_m"][r.orbit["param"] == 1.0], one.orbit["x1_m"], "seed 1")
