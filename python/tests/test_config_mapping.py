"""`Config` is a read-only mapping of the effective values: every key of the file with its
default where the file leaves it out, elements and derived keys, hashable and equal by its
effective values, with copies that change or remove keys; an unknown key says which keys
were probably meant."""

import collections.abc

import pytest

import vibrotribo as vt
from conftest import CONFIGS


def test_effective_values_by_key():
    c = vt.Config()
    assert isinstance(c, collections.abc.Mapping)
    # The paper's default case (configs/default.toml spells the same values out).
    d = vt.Config(CONFIGS / "default.toml")
    for key in ("excitation.amplitude", "oscillator.masses", "oscillator.gaps", "run.periods"):
        assert c[key] == d[key], key
    assert c["oscillator.masses"] == c.masses
    assert c["oscillator.gaps[1]"] == c.gaps[1]
    assert c["mass_ratio"] == pytest.approx(c.masses[1] / c.masses[0], rel=0, abs=0)
    assert c["omega_ratio"] == c.omega_ratio
    assert c.with_(amplitude=0.05)["excitation.amplitude"] == 0.05
    assert "excitation.amplitude" in c and "excitation.nonsense" not in c
    assert len(c) == len(list(c)) > 20
    assert dict(c)["run.periods"] == c.periods


def test_to_dict_holds_the_effective_values_and_round_trips():
    c = vt.Config()
    d = c.to_dict()
    assert d["oscillator"]["masses"] == c.masses and d["run"]["periods"] == c.periods
    assert vt.Config(d) == c
    assert c.settings() == {}


def test_hashable_and_equal_by_effective_values():
    a, b = vt.Config(), vt.Config(excitation__amplitude=vt.Config()["excitation.amplitude"])
    assert a == b and hash(a) == hash(b)
    assert len({a, b, vt.Config(amplitude=0.05)}) == 2


def test_without_restores_defaults():
    c = vt.Config(amplitude=0.05, run__periods=30)
    back = c.without("excitation.amplitude")
    assert back["excitation.amplitude"] == vt.Config()["excitation.amplitude"]
    assert back["run.periods"] == 30
    assert c.without("run") ["run.periods"] == vt.Config().periods
    with pytest.raises(KeyError, match="not set"):
        vt.Config().without("excitation.amplitude")


def test_unknown_keys_suggest_the_closest():
    with pytest.raises(KeyError, match=r"did you mean `excitation.amplitude`"):
        vt.Config(excitation__amplitdue=0.1)
    with pytest.raises(KeyError, match=r"did you mean .*`omega_ratio`"):
        vt.sweep(None, "omega_ratoi", [0.6])
    with pytest.raises(KeyError, match="did you mean"):
        vt.Config()["excitation.amplitdue"]
