"""A result's `settings` hold the keys of its command's manifest with the same values: the
command line and Python build both from the library's manifest types.

Documented differences:
- `CLI_ONLY`: the keys only an output directory has (a grid job's shard, a job's progress
  `complete`, `done` and `rows`, the wall time), which Python leaves out.
- `AXES`: where a manifest's axis is an object (`map.json`, `basins.json`: `x` and `y` with
  `param`, `from`, `to`, `steps`, `values`), Python's `settings` name the key (`x`) and list
  its values (`x_values`).
- `response` and `band-response` flatten the response's summary into their manifest; Python
  returns it as the result's `summary`. A chirp's runs and jumps (`up`, `down`,
  `hysteresis`) are the result's attributes of those names.
"""

import pytest

import vibrotribo as vt
from conftest import read_json, run_cli

CLI_ONLY = {"shard", "complete", "done", "rows", "wall_time_s"}


def assert_same_keys(settings, manifest, axes=(), elsewhere=None):
    """Every key of `manifest` but `CLI_ONLY` is in `settings` (or, for a summary flattened
    into the manifest, in `elsewhere`) with the same value; the axes `axes` as key and values."""
    elsewhere = elsewhere or {}
    missing = []
    for key, expected in manifest.items():
        if key in CLI_ONLY:
            continue
        if key in axes:
            assert settings[key] == expected["param"], key
            assert settings[f"{key}_values"] == expected["values"], key
            continue
        if key in settings:
            assert settings[key] == expected, key
        elif key in elsewhere:
            assert elsewhere[key] == expected, key
        else:
            missing.append(key)
    assert not missing, f"keys of the manifest that Python does not report: {missing}"


SWEEPS = [
    ("default", [], {}),
    ("continued-mechanics", ["--continuation", "up", "--mechanics-only"],
     dict(continuation="up", mechanics_only=True)),
    ("floquet-fixed", ["--floquet", "--settle", "fixed"], dict(floquet=True, settle="fixed")),
]


@pytest.mark.parametrize("name,args,kwargs", SWEEPS, ids=[s[0] for s in SWEEPS])
def test_sweep_settings_are_the_manifest(cli, tmp_path, name, args, kwargs):
    run_cli(cli, "sweep", "--param", "omega_ratio", "--from", "0.6", "--to", "0.7", "--steps", "2",
            "--transient", "20", "--recorded", "8", *args, "--out", tmp_path)
    r = vt.sweep(vt.Config(), "omega_ratio", vt.grid(0.6, 0.7, 2), transient=20, recorded=8, threads=1,
                 **kwargs)
    assert_same_keys(r.settings, read_json(tmp_path / "sweep.json"))


def test_map_settings_are_the_manifest(cli, tmp_path):
    run_cli(cli, "map", "--x", "omega_ratio", "--x-from", "0.6", "--x-to", "0.7", "--x-steps", "2",
            "--y", "gap_ratio", "--y-from", "1", "--y-to", "1.5", "--y-steps", "2",
            "--transient", "20", "--recorded", "8", "--out", tmp_path)
    r = vt.map(vt.Config(), "omega_ratio", vt.grid(0.6, 0.7, 2), "gap_ratio", vt.grid(1, 1.5, 2),
               transient=20, recorded=8, threads=1)
    assert_same_keys(r.settings, read_json(tmp_path / "map.json"), axes=("x", "y"))


def test_basins_settings_are_the_manifest(cli, tmp_path):
    run_cli(cli, "basins", "--x", "run.initial_positions[0]", "--x-from", "-0.01", "--x-to", "0.01",
            "--y", "run.initial_velocities[0]", "--y-from", "-0.2", "--y-to", "0.2", "--grid", "2x2",
            "--transient", "20", "--recorded", "8", "--mechanics-only", "--out", tmp_path)
    r = vt.basins(vt.Config(), "run.initial_positions[0]", -0.01, 0.01, "run.initial_velocities[0]", -0.2, 0.2,
                  (2, 2), transient=20, recorded=8, mechanics_only=True, threads=1)
    assert_same_keys(r.settings, read_json(tmp_path / "basins.json"), axes=("x", "y"))


def test_attractors_settings_are_the_manifest(cli, tmp_path):
    run_cli(cli, "attractors", "--param", "omega_ratio", "--from", "0.6", "--to", "0.7", "--steps", "2",
            "--samples", "3", "--transient", "20", "--recorded", "8", "--mechanics-only", "--out", tmp_path)
    r = vt.attractors(vt.Config(), "omega_ratio", vt.grid(0.6, 0.7, 2), samples=3, transient=20, recorded=8,
                      mechanics_only=True, threads=1)
    assert_same_keys(r.settings, read_json(tmp_path / "attractors.json"))


def test_response_settings_are_the_manifest(cli, tmp_path):
    run_cli(cli, "response", "--from", "0.7", "--to", "0.8", "--steps", "2", "--transient", "20",
            "--recorded", "8", "--out", tmp_path)
    r = vt.response(vt.Config(), vt.grid(0.7, 0.8, 2), transient=20, recorded=8)
    assert_same_keys(r.settings, read_json(tmp_path / "response.json"), elsewhere=r.summary)


def test_band_response_settings_are_the_manifest(cli, tmp_path):
    noise = tmp_path / "noise.toml"
    noise.write_text(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 4.0\nf_high_hz = 8.0\n"
        "seed = 1\nomega_ratio = 0.7\n[run]\nperiods = 12\ntransient_periods = 6\nstart_relative_to_base = true\n"
    )
    out = tmp_path / "out"
    run_cli(cli, "band-response", noise, "--from", "4", "--to", "8", "--steps", "2", "--seeds", "1",
            "--out", out)
    r = vt.band_response(vt.Config(noise), vt.grid(4, 8, 2), seeds=1, threads=1)
    m = read_json(out / "band_response.json")
    # The centres' range is the result's `centres_hz`.
    for key in ("from", "to", "steps"):
        m.pop(key)
    assert_same_keys(r.settings, m, elsewhere=r.summary)


def test_chirp_settings_are_the_manifest(cli, tmp_path):
    run_cli(cli, "chirp", "--from", "0.6", "--to", "0.9", "--duration", "3", "--samples-per-cycle", "20",
            "--out", tmp_path)
    r = vt.chirp(vt.Config(), 0.6, 0.9, 3, samples_per_cycle=20)
    m = read_json(tmp_path / "chirp.json")
    # The runs and their jumps are the result's `up`, `down` and `hysteresis`.
    for key in ("up", "down", "hysteresis"):
        m.pop(key)
    assert_same_keys(r.settings, m)
