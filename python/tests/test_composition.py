"""Every base motion with every electrical model and every kind of stop through `simulate` and
`sweep` in Python: each combination runs or is refused exactly as the command line's table in
docs/guide/src/composition.md says (written by the command line's `composition` test), a
refusal naming the combination and the reason."""

import math
import re

import pytest

import vibrotribo as vt

from conftest import CONFIGS, ROOT

PAGE = ROOT / "docs" / "guide" / "src" / "composition.md"
RECORD = CONFIGS / "records" / "rjob_vertical_acceleration.csv"

# The same combinations as crates/vibrotribo-cli/tests/cli/composition.rs.
MOTIONS = {
    "sine": ("", ""),
    "multisine": (
        'kind = "multisine"\nharmonics = [{amplitude = 0.05, ratio = 1}, '
        "{amplitude = 0.01, ratio = 2.3, phase = 1}]\n",
        "",
    ),
    "chirp": ('kind = "chirp"\namplitude = 0.05\nf_start_hz = 3\nf_end_hz = 6\n', ""),
    "random": (
        'kind = "random"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 20\nseed = 14\n',
        "",
    ),
    "record": (
        f'kind = "record"\nfile = "{RECORD}"\nquantity = "acceleration"\npeak_acceleration = 9.8\n',
        "",
    ),
}
MODELS = {
    "mechanics only": ("", True),
    "one-way": ('voc_model = "exact"\n', False),
    "two-way": ('voc_model = "exact"\ncoupling = "two_way"\n', False),
}
STOPS = {
    "none": "",
    "fixed": 'gap = 0.03\nrestitution = 0.8\nframe = "fixed"\n',
    "moving with the base": 'gap = 0.03\nrestitution = 0.8\nframe = "base"\n',
}


def rows():
    """The table's rows: (motion, model, stop, simulate cell, sweep cell)."""
    out = []
    for line in PAGE.read_text().splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        if len(cells) == 5 and cells[0] in MOTIONS:
            out.append(tuple(cells))
    return out


ROWS = rows()


def config_for(tmp_path, motion, model, stop):
    excitation, run = MOTIONS[motion]
    text = (
        f"[excitation]\n{excitation}[harvester]\n{MODELS[model][0]}"
        f"[run]\nperiods = 3\ntransient_periods = 1\nsamples_per_period = 20\n{run}"
    )
    if STOPS[stop]:
        text += f"[oscillator.stops.upper]\n{STOPS[stop]}"
    path = tmp_path / "case.toml"
    path.write_text(text)
    return vt.Config(path)


def check_refusal(cell, error, motion):
    message = str(error)
    assert motion in message and 'frame = "base"' in message, message
    assert cell.startswith("refused: "), cell


def test_the_table_covers_every_combination():
    assert {(r[0], r[1], r[2]) for r in ROWS} == {
        (m, e, s) for m in MOTIONS for e in MODELS for s in STOPS
    }


@pytest.mark.parametrize("motion,model,stop,cell", [r[:4] for r in ROWS],
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in ROWS])
def test_simulate(tmp_path, motion, model, stop, cell):
    mechanics_only = MODELS[model][1]
    if cell == "runs":
        config = config_for(tmp_path, motion, model, stop)
        r = vt.simulate(config, mechanics_only=mechanics_only)
        assert r.summary["periods"] == 3
        if mechanics_only:
            assert r.q is None
        else:
            p = r.summary["average_power_w"]
            assert p > 0 and math.isfinite(p)
    else:
        with pytest.raises(Exception) as e:
            vt.simulate(config_for(tmp_path, motion, model, stop), mechanics_only=mechanics_only)
        check_refusal(cell, e.value, motion)


@pytest.mark.parametrize("motion,model,stop,cell", [r[:3] + r[4:] for r in ROWS],
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in ROWS])
def test_sweep(tmp_path, motion, model, stop, cell):
    mechanics_only = MODELS[model][1]

    def run():
        return vt.sweep(config_for(tmp_path, motion, model, stop), "oscillator.restitution",
                        [0.7, 0.8], transient=1, recorded=2, mechanics_only=mechanics_only,
                        settle="fixed")

    if cell == "runs":
        r = run()
        assert r.summary.rows == 2
        assert (r.summary["error"] == "").all()
        p = r.summary["average_power_w"]
        if mechanics_only:
            assert all(math.isnan(x) for x in p)
        else:
            assert all(x > 0 and math.isfinite(x) for x in p)
    else:
        with pytest.raises(Exception) as e:
            run()
        check_refusal(cell, e.value, motion)
