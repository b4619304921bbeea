"""vibrotribo.Config: the same keys as the TOML file, from a path, a dict or keyword
overrides; and every bad input raises the right exception with the key (or file) named."""

import pickle

import pytest

import vibrotribo as vt
from conftest import CONFIGS


def test_sources_agree():
    from_file = vt.Config(CONFIGS / "chatter.toml")
    from_str_path = vt.Config(str(CONFIGS / "chatter.toml"))
    from_dict = vt.Config(
        {"oscillator": {"masses": [0.05, 0.15, 0.05], "gaps": [0.005, 0.005]},
         "excitation": {"omega_ratio": 0.6}}
    )
    from_kwargs = vt.Config(oscillator__masses=[0.05, 0.15, 0.05], gap=0.005, omega_ratio=0.6)
    assert from_file == from_str_path == from_dict
    assert from_kwargs.masses == from_dict.masses and from_kwargs.gaps == from_dict.gaps
    assert from_kwargs.omega_ratio == 0.6
    assert vt.Config(vt.Config.from_toml((CONFIGS / "chatter.toml").read_text())) == from_file


def test_key_conventions():
    dotted = vt.Config(**{"excitation.omega_ratio": 0.6, "oscillator.gaps[1]": 0.03})
    underscored = vt.Config(excitation__omega_ratio=0.6).replace(**{"oscillator.gaps[1]": 0.03})
    assert dotted == underscored
    assert dotted.gaps == [0.02, 0.03]
    # Derived keys: m2 = R_m·m1 with m1 fixed.
    c = vt.Config({"oscillator": {"masses": [0.05, 0.1, 0.05]}}, mass_ratio=3)
    assert c.masses == [0.05, 3 * 0.05, 0.05]
    # Overrides are validated together (transient < periods only as a whole).
    c = vt.Config(run__periods=20, run__transient_periods=10)
    assert (c.periods, c.transient_periods) == (20, 10)
    # numpy values are accepted.
    import numpy as np

    c = vt.Config(oscillator__masses=np.array([0.05, 0.15, 0.05]), amplitude=np.float64(0.07))
    assert c.masses == [0.05, 0.15, 0.05]
    assert "excitation.omega_ratio" in vt.Config.keys() and "mass_ratio" in vt.Config.keys()


def test_round_trips():
    c = vt.Config(CONFIGS / "chatter.toml", mass_ratio=2.5, harvester__load="rectifier")
    assert vt.Config(c.to_dict()) == c
    assert vt.Config.from_toml(c.to_toml()) == c
    assert pickle.loads(pickle.dumps(c)) == c
    assert eval(repr(c), {"Config": vt.Config}) == c


def test_a_record_path_is_resolved_once(tmp_path, monkeypatch):
    """A record's path relative to its configuration file is stored resolved, so that the
    dict, the TOML text and a pickle (what Dask sends to a worker) read the same record from
    any working directory."""
    c = vt.Config(CONFIGS / "record_default.toml")
    monkeypatch.chdir(tmp_path)
    assert vt.Config(c.to_dict()) == c
    assert vt.Config.from_toml(c.to_toml()) == c
    assert pickle.loads(pickle.dumps(c)) == c


def raises(exc, *fragments):
    """A context that expects `exc` whose message contains every fragment."""

    class Expect:
        def __enter__(self):
            self.ctx = pytest.raises(exc)
            self.info = self.ctx.__enter__()
            return self.info

        def __exit__(self, *a):
            handled = self.ctx.__exit__(*a)
            message = str(self.info.value)
            for f in fragments:
                assert f in message, f"{f!r} not in {message!r}"
            return handled

    return Expect()


@pytest.mark.parametrize(
    "make,exc,named",
    [
        (lambda: vt.Config(foo=1), KeyError, "`foo`"),
        (lambda: vt.Config(oscillator__mases=[1.0]), KeyError, "`oscillator.mases`"),
        (lambda: vt.Config({"oscillator": {"mases": [0.1, 0.2]}}), KeyError, "oscillator.mases"),
        (lambda: vt.Config({"oscilator": {"masses": [0.1, 0.2]}}), KeyError, "oscilator.masses"),
        (lambda: vt.Config({"mass_ratio": 3}), KeyError, "mass_ratio"),
        (lambda: vt.Config(oscillator__masses=[0.1, -1.0, 0.1]), ValueError, "oscillator.masses[1]"),
        (lambda: vt.Config(**{"oscillator.masses[1]": -1.0}), ValueError, "oscillator.masses[1]"),
        (lambda: vt.Config(**{"oscillator.gaps[5]": 0.01}), ValueError, "oscillator.gaps[5]"),
        (lambda: vt.Config(run__periods="many"), ValueError, "run.periods"),
        (lambda: vt.Config(run__periods=20.5), ValueError, "run.periods"),
        (lambda: vt.Config({"run": {"periods": -3}}), ValueError, "run.periods"),
        (lambda: vt.Config(excitation__omega_ratio=float("nan")), ValueError, "excitation.omega_ratio"),
        (lambda: vt.Config(mass_ratio=-2), ValueError, "mass_ratio"),
        (lambda: vt.Config(harvester__load="battery"), ValueError, "harvester"),
        (lambda: vt.Config(run__initial_positions=None), ValueError, "run.initial_positions"),
        (lambda: vt.Config({"run": {"periods": None}}), ValueError, "run.periods"),
        (lambda: vt.Config(run__periods=object()), ValueError, "run.periods"),
        (lambda: vt.Config(run__periods=10, run__transient_periods=10), ValueError, "transient_periods"),
        (lambda: vt.Config("no/such/file.toml"), FileNotFoundError, "no/such/file.toml"),
        (lambda: vt.Config.from_toml("[oscillator\nmasses = 1"), ValueError, "TOML"),
        (lambda: vt.Config(12), TypeError, "Config takes"),
    ],
)
def test_bad_config_input(make, exc, named):
    with raises(exc, named):
        make()


def test_bad_toml_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[oscillator]\nmasses = [0.1, 0.2\n")
    with raises(ValueError, str(bad)):
        vt.Config(bad)
    typo = tmp_path / "typo.toml"
    typo.write_text("[oscillator]\nmases = [0.1, 0.2]\n")
    with raises(ValueError, "mases"):
        vt.Config(typo)


@pytest.mark.parametrize(
    "call,exc,named",
    [
        (lambda: vt.sweep(None, "omega_ratoi", [0.6]), KeyError, "omega_ratoi"),
        (lambda: vt.sweep(None, "omega_ratio", [0.6, -1.0]), ValueError, "excitation.omega_ratio"),
        (lambda: vt.sweep(None, "oscillator.masses[1]", [0.1, 0.0]), ValueError, "oscillator.masses[1]"),
        (lambda: vt.sweep(None, "omega_ratio", [0.6], recorded=0), ValueError, "recorded"),
        (lambda: vt.sweep(None, "omega_ratio", [0.6], threads=0), ValueError, "threads"),
        (lambda: vt.sweep(None, "omega_ratio", [0.6], period_tolerance=2.0), ValueError, "period_tolerance"),
        (lambda: vt.sweep(None, "omega_ratio", [0.6], continuation="sideways"), ValueError, "sideways"),
        (lambda: vt.sweep(None, "omega_ratio", [[0.6]]), ValueError, "values"),
        (lambda: vt.sweep(None, "omega_ratio", [float("inf")]), ValueError, "values"),
        (lambda: vt.map(None, "omega_ratio", [0.6], "gap_ratoi", [1.0]), KeyError, "gap_ratoi"),
        (lambda: vt.simulate({"run": {"periodz": 3}}), KeyError, "run.periodz"),
        (lambda: vt.periodic(None, guess=([0.0], [0.0]), period=1), ValueError, "guess"),
        (lambda: vt.periodic(None, guess=([0.0] * 3, [0.0] * 3)), ValueError, "period"),
        (lambda: vt.continue_(None, "omega_ratio", 0.7, -0.1), ValueError, "excitation.omega_ratio"),
        (lambda: vt.continue_(None, "omega_ratoi", 0.7, 0.8), KeyError, "omega_ratoi"),
        (lambda: vt.load_sweep(None, low=-1.0), ValueError, "low"),
        (lambda: vt.load_sweep(None, steps=0), ValueError, "steps"),
        (lambda: vt.load_sweep(None, resistances=[1e5, 0.0]), ValueError, "resistances"),
        (lambda: vt.load_sweep({"harvester": {"load_resistanse": 1e5}}), KeyError, "harvester.load_resistanse"),
    ],
)
def test_bad_run_input(call, exc, named):
    with raises(exc, named):
        call()
