"""`vibrotribo.continue_` and `vibrotribo continue` share their defaults and give the same
branches from the same configuration, point by point and bit for bit: the parameter, the
state, the spectral radius, stability, sticking and the arclength of every point, and the
bifurcations located on the way."""

import subprocess

import numpy as np

import vibrotribo as vt
from conftest import assert_bits, numbers, read_csv


def test_python_and_cli_continue_give_the_same_branch(cli, tmp_path):
    out = tmp_path / "continue"
    p = subprocess.run(
        [str(cli), "continue", "--param", "omega_ratio", "--from", "0.7", "--to", "1.0", "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, f"vibrotribo continue failed:\n{p.stderr}"
    c = vt.continue_(vt.Config(), "omega_ratio", 0.7, 1.0)
    _, cols = read_csv(out / "branch.csv")
    branch = numbers(cols["branch"]).astype(int)
    assert sorted(set(branch.tolist())) == list(range(len(c.branches))), (
        f"the command line has branches {sorted(set(branch.tolist()))}, Python {len(c.branches)}"
    )
    for i, b in enumerate(c.branches):
        rows = branch == i
        pts = b.points
        what = f"branch {i}"
        assert int(rows.sum()) == len(pts["parameter"]), (
            f"{what}: {int(rows.sum())} points on the command line, {len(pts['parameter'])} in Python"
        )
        assert_bits(pts["parameter"], numbers(cols["param"])[rows], f"{what} param")
        assert_bits(pts["arclength"], numbers(cols["arclength"])[rows], f"{what} arclength")
        assert_bits(pts["spectral_radius"], numbers(cols["max_abs_multiplier"])[rows], f"{what} max |μ|")
        for k in range(pts["x"].shape[1]):
            assert_bits(pts["x"][:, k], numbers(cols[f"x{k + 1}_m"])[rows], f"{what} x{k + 1}")
            assert_bits(pts["v"][:, k], numbers(cols[f"v{k + 1}_m_s"])[rows], f"{what} v{k + 1}")
        stable = np.array([s == "true" for s in np.array(cols["stable"])[rows]])
        assert (np.asarray(pts["stable"], dtype=bool) == stable).all(), f"{what}: stability differs"
        sticks = np.array([s == "true" for s in np.array(cols["sticks"])[rows]])
        assert (np.asarray(pts["sticks"], dtype=bool) == sticks).all(), f"{what}: sticking differs"
        assert b.period == int(numbers(cols["period"])[rows][0]), f"{what}: period differs"
        # The harvester along the branch and the smallest closing speed, as branch.csv.
        assert_bits(pts["average_power_w"], numbers(cols["average_power_w"])[rows], f"{what} power")
        assert_bits(pts["min_closing_speed_m_s"], numbers(cols["min_closing_speed_m_s"])[rows], f"{what} closing")
    _, bif = read_csv(out / "bifurcations.csv")
    got = [(b["branch"], b["parameter"]) for b in c.bifurcations]
    expected = list(zip(numbers(bif["branch"]).astype(int).tolist(), numbers(bif["param"]).tolist()))
    assert len(got) == len(expected), f"bifurcations: Python {got}, command line {expected}"
    for (gb, gp), (eb, ep) in zip(got, expected):
        assert gb == eb and np.float64(gp).view(np.uint64) == np.float64(ep).view(np.uint64), (
            f"bifurcation: Python ({gb}, {gp!r}), command line ({eb}, {ep!r})"
        )
