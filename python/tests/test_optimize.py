"""`vibrotribo.optimize` searches as `vibrotribo optimize` does: the same seed gives the same
designs, best values and objective bit for bit, and the best design's TOML runs to that
objective."""

import json
import subprocess

import numpy as np
import pytest

import vibrotribo as vt
from conftest import assert_bits

SETS = {"run.periods": 40, "run.transient_periods": 20}
ARGS = dict(particles=4, swarm_iterations=1, local_iterations=4, seed=3)


def test_optimize_equals_the_command(cli, tmp_path):
    vary = ["harvester.load_resistance=1e9..1e12"]
    cmd = [str(cli), "optimize", "--vary", vary[0], "--out", str(tmp_path / "opt"), "-q",
           "--particles", "4", "--swarm-iterations", "1", "--local-iterations", "4", "--seed", "3"]
    for k, v in SETS.items():
        cmd += ["--set", f"{k}={v}"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    files = json.loads((tmp_path / "opt" / "optimize.json").read_text())
    r = vt.optimize(vt.Config(**{k.replace(".", "__"): v for k, v in SETS.items()}), vary, **ARGS)
    key = "harvester.load_resistance"
    assert_bits(np.array([r["best"][key]]), np.array([files["best"][key]]), "best load")
    assert_bits(np.array([r["objective"]]), np.array([files["objective"]]), "objective")
    # The best design, run as a configuration, gives the objective.
    best = tmp_path / "best.toml"
    best.write_text(r["best_config"])
    run = vt.simulate(vt.Config(str(best)), samples=False)
    power = run.summary["average_power_w"]
    assert abs(power - r["objective"]) <= 1e-12 * abs(r["objective"]), (power, r["objective"])


def test_optimize_names_a_bad_range():
    with pytest.raises(ValueError, match="load_resistance"):
        vt.optimize(vt.Config(), ["harvester.load_resistance=1e12..1e9"], **ARGS)
    with pytest.raises(ValueError, match="vary"):
        vt.optimize(vt.Config(), [], **ARGS)
