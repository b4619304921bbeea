"""Every command and option of the `vibrotribo` program has a Python counterpart, and the
counterparts' numbers equal the program's files bit for bit.

The subcommands and their options are read from the program's own `--help`, so that a new
command or option without a counterpart fails `test_every_option_has_a_python_counterpart`.
`PARITY` is the documented mapping (the guide's Python page shows it as a table): each option
maps to a parameter of the Python function (checked to exist, with the same default where
`--help` shows one), or is listed as inherently command-line with the reason."""

import inspect
import re
import subprocess

import numpy as np
import pytest

import vibrotribo as vt
from conftest import CONFIGS, assert_bits, compare_tables, numbers, read_csv, read_json

# Why an option has no Python parameter.
FILES = "CLI only: writes files; Python returns the result object (write it with to_pandas().to_csv)"
PLOT = "CLI only: draws pictures; in Python plot the arrays (matplotlib)"
QUIET = "CLI only: the progress bar; Python prints nothing"
SHARD = "CLI only: splits a job into directories to merge; Python spreads work with vibrotribo.dask"
RESUME = "CLI only: continues a job from its files; a Python result is held in memory"
SET = "the configuration: Config(**{key: value}) or Config(...).with_(...)"
HELP = "CLI only: help text"

RUN = {
    "--transient": "transient",
    "--recorded": "recorded",
    "--mechanics-only": "mechanics_only",
    "--period-tolerance": "period_tolerance",
    "--floquet": "floquet",
    "--settle": "settle",
    "--settle-cap": "settle_cap",
    "--threads": "threads",
    "--allow-large": "allow_large",
    "-q": None,
}
COMMON = {"--set": None, "-h": None, "--help": None, "--force": None}

# command → (Python function, {option: parameter or None (CLI only)}).
PARITY = {
    "simulate": (vt.simulate, {
        "<CONFIG>": "config", "--out": None, "--mechanics-only": "mechanics_only", "--plot": None,
        "-q": None, "--allow-large": "allow_large", "--settle": "settle", "--settle-cap": "settle_cap",
    }),
    "load-sweep": (vt.load_sweep, {
        "<CONFIG>": "config", "--from": "low", "--to": "high", "--steps": "steps",
        "--vq-points": "vq_points", "--out": None, "--plot": None, "-q": None,
        "--allow-large": "allow_large",
    }),
    "export-spice": (vt.export_spice, {
        "<RUN_DIR>": "config", "--from-period": "from_period", "--periods": "periods",
        "--dt-fraction": "dt_fraction", "--name": None, "--check": "check",
        "--allow-large": "allow_large",
    }),
    "periodic": (vt.periodic, {
        "<CONFIG>": "config", "--period": "period", "--transient": "transient",
        "--mechanics-only": "mechanics_only", "--out": None, "--plot": None, "-q": None,
    }),
    "continue": (vt.continue_, {
        "<CONFIG>": "config", "--param": "param", "--from": "start", "--to": "stop",
        "--period": "period", "--transient": "transient", "--doublings": "doubling_depth",
        "--max-points": "max_points", "--mechanics-only": "mechanics_only", "--out": None,
        "--plot": None, "--diagram-steps": None, "--mass": None, "-q": None,
    }),
    "curve": (vt.curve, {
        "<CONFIG>": "config", "--kind": "kind", "--param": "param", "--near": "near",
        "--param2": "param2", "--from2": "from2", "--to2": "to2", "--period": "period",
        "--window": "window", "--transient": "transient", "--max-points": "max_points",
        "--mechanics-only": "mechanics_only", "--out": None,
    }),
    "bifmap": (vt.bifmap, {
        "<CONFIG>": "config", "--x": "x", "--x-from": "x_values", "--x-to": "x_values",
        "--x-steps": "x_values", "--y": "y", "--y-from": "y_values", "--y-to": "y_values",
        "--y-steps": "y_values", "--seeds": "seeds", "--x-starts": "x_starts", "--kinds": "kinds",
        "--period": "period", "--doublings": "doublings", "--orbit-transient": "orbit_transient",
        "--branch-points": "branch_points", "--curve-points": "curve_points",
        "--max-curves": "max_curves", "--out": None, "--plot": None, **RUN,
    }),
    "sweep": (vt.sweep, {
        "<CONFIG>": "config", "--param": "param", "--from": "values", "--to": "values",
        "--steps": "values", "--continuation": "continuation", "--shard": None, "--out": None,
        "--resume": None, "--plot": None, "--lyapunov": "lyapunov", **RUN,
    }),
    "chirp": (vt.chirp, {
        "<CONFIG>": "config", "--from": "from_", "--to": "to", "--duration": "duration",
        "--sweep": "sweep", "--amplitude": "amplitude", "--mechanics-only": "mechanics_only",
        "--from-rest": "from_rest", "--samples-per-cycle": "samples_per_cycle",
        "--jump-window": "jump_window", "--out": None, "--plot": None, "-q": None,
    }),
    "map": (vt.map, {
        "<CONFIG>": "config", "--x": "x", "--x-from": "x_values", "--x-to": "x_values",
        "--x-steps": "x_values", "--y": "y", "--y-from": "y_values", "--y-to": "y_values",
        "--y-steps": "y_values", "--out": None, "--shard": None, "--resume": None, "--plot": None,
        **RUN,
    }),
    "optimize-mass-ratio": (vt.optimize_mass_ratio, {
        "<CONFIG>": "config", "--omega-from": "omega_from", "--omega-to": "omega_to",
        "--omega-steps": "omega_steps", "--rm-from": "rm_from", "--rm-to": "rm_to",
        "--rm-steps": "rm_steps", "--out": None, "--plot": None,
        **dict(RUN, **{"--mechanics-only": None}),
    }),
    "basins": (vt.basins, {
        "<CONFIG>": "config", "--x": "x", "--x-from": "x_from", "--x-to": "x_to", "--y": "y",
        "--y-from": "y_from", "--y-to": "y_to", "--grid": "grid", "--out": None, "--shard": None,
        "--resume": None, "--plot": None, "--cell": "cell", "--section-tolerance": "section_tolerance",
        "--match-tolerance": "match_tolerance", **RUN,
    }),
    "attractors": (vt.attractors, {
        "<CONFIG>": "config", "--param": "param", "--from": "values", "--to": "values",
        "--steps": "values", "--samples": "samples", "--seed": "seed",
        "--position-range": "position_range", "--velocity-range": "velocity_range", "--out": None,
        "--plot": None, "--cell": "cell", "--section-tolerance": "section_tolerance",
        "--match-tolerance": "match_tolerance", "--continuation-distance": "continuation_distance",
        **RUN,
    }),
    "optimize": (vt.optimize, {
        "<CONFIG>": "config", "--vary": "vary", "--objective": "objective",
        "--constraint": "constraint", "--starts": "starts", "--seed": "seed",
        "--particles": "particles", "--swarm-iterations": "swarm_iterations",
        "--local-iterations": "local_iterations", "--out": None, "--resume": None, "-q": None,
    }),
    "response": (vt.response, {
        "<CONFIG>": "config", "--param": "param", "--from": "values", "--to": "values",
        "--steps": "values", "--branches": "branches", "--branch-seeds": "branch_seeds",
        "--out": None, "--plot": None, **RUN,
    }),
    "band-response": (vt.band_response, {
        "<CONFIG>": "config", "--from": "centres_hz", "--to": "centres_hz", "--steps": "centres_hz",
        "--width": "width", "--seeds": "seeds", "--out": None, "--plot": None, **RUN,
    }),
    "lyapunov": (vt.lyapunov, {
        "<CONFIG>": "config", "--periods": "periods", "--transient": "transient", "--seed": "seed",
        "--batches": "batches", "--out": None, "--plot": None, "-q": None,
        "--allow-large": "allow_large",
    }),
}

# Commands with no Python function, and why.
CLI_ONLY = {
    "merge": "combines the shard directories of one job; Python jobs are not split into directories "
    "(vibrotribo.dask spreads a sweep or a map over a cluster and returns one result)",
    "plot": "draws the pictures of an output directory; in Python plot the result arrays",
    "reproduce": "recomputes the paper's whole study into REPORT.md; its pieces are the Python "
    "functions (sweep, map, optimize_mass_ratio, load_sweep, continue_)",
    "serve": "serves the interactive explorer to a browser; in a notebook call the functions "
    "(simulate, sweep, map, basins) and plot their arrays",
    "help": HELP,
}

# Why a mapped option is None, by option.
REASONS = {"--force": "CLI only: writes over another job's files; a Python result is held in memory",
           "--out": FILES, "--plot": PLOT, "-q": QUIET, "--shard": SHARD, "--resume": RESUME,
           "--name": "CLI only: the netlist's file name; SpiceExport.write(path) writes it anywhere",
           "--diagram-steps": PLOT, "--mass": PLOT,
           "--mechanics-only": "refused by the command (the optimum maximises power)"}


def help_text(cli, *args):
    p = subprocess.run([str(cli), *args, "--help"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p.stdout


def subcommands(cli):
    text = help_text(cli).split("Commands:")[1].split("Options:")[0]
    return [line.split()[0] for line in text.splitlines() if line.strip()]


def options(cli, command):
    """The options of a subcommand: `--long` names, `-q` for a short-only flag, positional
    `<NAME>`, each with the default its help shows (or None)."""
    text = help_text(cli, command)
    out = {}
    if "Arguments:" in text:
        for line in text.split("Arguments:")[1].split("Options:")[0].splitlines():
            m = re.match(r"\s+[\[<]([A-Z_]+)[\]>]", line)
            if m:
                out[f"<{m.group(1)}>"] = None
    name = None
    for line in text.split("Options:")[-1].splitlines():
        m = re.match(r"\s+(?:(-\w), )?(--[\w-]+)", line)
        if m:
            name = "-q" if m.group(2) == "--quiet" else m.group(2)
            out[name] = None
        # The default closes the option's help, on its first line or a later one.
        default = re.search(r"\[default: ([^\]]+)\]", line)
        if default and name is not None:
            out[name] = default.group(1)
    return out


def test_every_command_has_a_python_counterpart(cli):
    missing = [c for c in subcommands(cli) if c not in PARITY and c not in CLI_ONLY]
    assert not missing, f"commands without a Python counterpart or a stated reason: {missing}"


@pytest.mark.parametrize("command", sorted(PARITY))
def test_every_option_has_a_python_counterpart(cli, command):
    function, mapping = PARITY[command]
    parameters = inspect.signature(function).parameters
    for option, default in options(cli, command).items():
        if option in COMMON:
            continue
        assert option in mapping, f"vibrotribo {command} {option}: no Python counterpart in the parity table"
        name = mapping[option]
        if name is None:
            assert option in REASONS, f"{command} {option}: CLI-only without a reason"
            continue
        assert name in parameters, f"vibrotribo {command} {option}: vt.{function.__name__} has no `{name}`"
        python_default = parameters[name].default
        if default is not None and python_default is not inspect.Parameter.empty and python_default is not None:
            if isinstance(python_default, bool):
                continue
            if isinstance(python_default, (int, float)):
                assert float(default) == float(python_default), (
                    f"{command} {option}: default {default} on the command line, {python_default} in Python"
                )
            else:
                assert str(python_default) == default, (
                    f"{command} {option}: default {default!r} on the command line, {python_default!r} in Python"
                )


def cli_run(cli, *args):
    p = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, f"vibrotribo {' '.join(map(str, args))} failed:\n{p.stderr}"
    return p


def test_chirp_equals_the_files(cli, tmp_path):
    cli_run(cli, "chirp", "--from", "0.6", "--to", "0.9", "--duration", "3", "--samples-per-cycle", "40",
            "--out", tmp_path, "-q")
    r = vt.chirp(vt.Config(), 0.6, 0.9, 3, samples_per_cycle=40)
    compare_tables([r.response], tmp_path, ["response.csv"])
    m = read_json(tmp_path / "chirp.json")
    for d in ("up", "down"):
        for k in ("f_start_hz", "run_duration_s", "periods", "cycles", "impacts", "complete"):
            assert getattr(r, d)[k] == m[d][k], (d, k)
        if m[d]["jump"] is None:
            assert getattr(r, d)["jump"] is None
        else:
            assert getattr(r, d)["jump"] == m[d]["jump"], d
    assert r.hysteresis == m["hysteresis"]
    assert r.response.rows > 10 and set(r.response["direction"]) == {"up", "down"}


def test_basins_equal_the_files(cli, tmp_path):
    args = ["--x", "run.initial_positions[0]", "--x-from", "-0.03", "--x-to", "0.03",
            "--y", "run.initial_velocities[0]", "--y-from", "-0.5", "--y-to", "0.5", "--grid", "4x3",
            "--transient", "60", "--recorded", "20", "--mechanics-only"]
    cli_run(cli, "basins", *args, "--out", tmp_path, "-q")
    r = vt.basins(vt.Config(), "run.initial_positions[0]", -0.03, 0.03, "run.initial_velocities[0]", -0.5, 0.5,
                  (4, 3), transient=60, recorded=20, mechanics_only=True, threads=2)
    compare_tables([r.basins, r.attractors], tmp_path, ["basins.csv", "attractors.csv"])
    # The first mass 30 mm below its rest position and the second at rest: their 20 mm gap
    # is closed, a start that cannot run (as the command line skips it).
    assert (r.basins["attractor"] == -1).sum() == (r.starts["error"] != "").sum()


def test_attractors_equal_the_files(cli, tmp_path):
    args = ["--param", "omega_ratio", "--from", "0.6", "--to", "0.7", "--steps", "2", "--samples", "6",
            "--transient", "60", "--recorded", "20", "--mechanics-only"]
    cli_run(cli, "attractors", *args, "--out", tmp_path, "-q")
    r = vt.attractors(vt.Config(), "omega_ratio", vt.grid(0.6, 0.7, 2), samples=6, transient=60, recorded=20,
                      mechanics_only=True, threads=1)
    compare_tables([r.attractors, r.expected_power], tmp_path, ["attractors.csv", "expected_power.csv"])


def test_optimize_mass_ratio_equals_the_files(cli, tmp_path):
    args = ["--omega-steps", "3", "--rm-from", "1.5", "--rm-to", "4", "--rm-steps", "5",
            "--transient", "30", "--recorded", "10"]
    cli_run(cli, "optimize-mass-ratio", *args, "--out", tmp_path, "-q")
    r = vt.optimize_mass_ratio(omega_steps=3, rm_from=1.5, rm_to=4, rm_steps=5, transient=30, recorded=10)
    compare_tables([r.power_grid, r.optimum], tmp_path, ["power_grid.csv", "optimum.csv"])
    fit = read_json(tmp_path / "fit.json")
    assert (r.fit is None) == (fit["fit"] is None)
    if r.fit is not None:
        for k in ("a", "b", "c"):
            assert_bits(np.array([r.fit[k]]), np.array([fit["fit"][k]]), f"fit {k}")
    assert r.power().shape == (3, 5)


def test_export_spice_equals_the_file(cli, tmp_path):
    sets = ["--set", "run.periods=12", "--set", "run.transient_periods=6"]
    cli_run(cli, "simulate", *sets, "--out", tmp_path, "-q")
    cli_run(cli, "export-spice", tmp_path, "--periods", "1", "--dt-fraction", "0.01")
    run = vt.simulate(vt.Config(run__periods=12, run__transient_periods=6), samples=False)
    r = vt.export_spice(run, periods=1, dt_fraction=0.01)
    assert r.netlist == (tmp_path / "harvester.cir").read_text()
    assert r.from_period == 6 and r.pwl_gaps_m.shape == (len(r.pwl_times_s), 2)
    with pytest.raises(ValueError, match="dt_fraction"):
        vt.export_spice(run, dt_fraction=2.0)


def test_simulate_settle_auto_equals_the_files(cli, tmp_path):
    cli_run(cli, "simulate", "--settle", "auto", "--set", "run.periods=20", "--set", "run.transient_periods=10",
            "--out", tmp_path, "-q")
    r = vt.simulate(vt.Config(run__periods=20, run__transient_periods=10), settle="auto")
    summary = read_json(tmp_path / "summary.json")
    assert r.summary["settle"] == summary["settle"] == "auto"
    assert r.summary["motion"]["settle_periods"] == summary["motion"]["settle_periods"]
    assert_bits(np.array([r.average_power_w]), np.array([summary["average_power_w"]]), "average power")
    _, cols = read_csv(tmp_path / "trajectory.csv")
    assert_bits(r.x[:, 0], numbers(cols["x1_m"]), "x1 after settling")


def test_sweep_floquet_and_lyapunov_and_map_floquet_equal_the_files(cli, tmp_path):
    cli_run(cli, "sweep", "--param", "omega_ratio", "--from", "0.6", "--to", "0.8", "--steps", "3",
            "--transient", "40", "--recorded", "16", "--mechanics-only", "--floquet", "--lyapunov",
            "--out", tmp_path / "s", "-q")
    r = vt.sweep(vt.Config(), "omega_ratio", vt.grid(0.6, 0.8, 3), transient=40, recorded=16,
                 mechanics_only=True, floquet=True, lyapunov=True)
    assert "max_abs_multiplier" in r.summary.columns and "lyapunov_max_1_s" in r.summary.columns
    compare_tables([r.summary, r.orbit, r.impacts], tmp_path / "s", ["summary.csv", "orbit.csv", "impacts.csv"])
    cli_run(cli, "map", "--x", "omega_ratio", "--x-from", "0.6", "--x-to", "0.7", "--x-steps", "2",
            "--y", "gap_ratio", "--y-from", "1", "--y-to", "1.5", "--y-steps", "2", "--transient", "30",
            "--recorded", "12", "--floquet", "--out", tmp_path / "m", "-q")
    m = vt.map(vt.Config(), "omega_ratio", vt.grid(0.6, 0.7, 2), "gap_ratio", vt.grid(1, 1.5, 2),
               transient=30, recorded=12, floquet=True)
    compare_tables([m.summary], tmp_path / "m", ["map.csv"])


def test_periodic_power_equals_the_file(cli, tmp_path):
    cli_run(cli, "periodic", "--out", tmp_path)
    o = vt.periodic(vt.Config())
    m = read_json(tmp_path / "periodic.json")
    assert o.average_power_w is not None
    assert_bits(np.array([o.average_power_w]), np.array([m["average_power_w"]]), "average power on the orbit")
    assert vt.periodic(vt.Config(), mechanics_only=True).average_power_w is None


def test_response_equals_the_files(cli, tmp_path):
    sets = ["--set", "excitation.amplitude=0.002"]
    cli_run(cli, "response", *sets, "--from", "0.7", "--to", "0.8", "--steps", "3", "--branches",
            "--branch-seeds", "2", "--out", tmp_path, "-q")
    r = vt.response(vt.Config(excitation__amplitude=0.002), vt.grid(0.7, 0.8, 3), branches=True, branch_seeds=2)
    compare_tables([r.response, r.branches], tmp_path, ["response.csv", "branches.csv"])
    m = read_json(tmp_path / "response.json")
    for k in ("bandwidth", "up", "down", "seeding", "branches", "complete"):
        assert r.summary[k] == m[k], k
    assert r.bandwidth is not None and r.branches.rows > 0


def test_band_response_equals_the_files(cli, tmp_path):
    noise = tmp_path / "noise.toml"
    noise.write_text(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 4.0\nf_high_hz = 8.0\n"
        "seed = 1\nomega_ratio = 0.7\n[run]\nperiods = 16\ntransient_periods = 6\nstart_relative_to_base = true\n"
    )
    out = tmp_path / "out"
    cli_run(cli, "band-response", noise, "--from", "4", "--to", "8", "--steps", "3", "--seeds", "2",
            "--out", out, "-q")
    r = vt.band_response(vt.Config(noise), vt.grid(4, 8, 3), seeds=2, threads=2)
    compare_tables([r.response, r.seeds], out, ["response.csv", "seeds.csv"])
    m = read_json(out / "band_response.json")
    for k in ("centres_hz", "width_hz", "rms_acceleration", "seeds", "bandwidth", "failed", "complete"):
        assert r.summary[k] == m[k], k
    assert r.seeds.rows == 6
