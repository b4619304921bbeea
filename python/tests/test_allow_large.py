"""A random excitation past the build limit of 10⁹ harmonic evaluations was refused when the
`Config` was made, with no way to allow it, and `vibrotribo lyapunov --allow-large` had no
Python counterpart. `Config(..., allow_large=True)` (kept by the configurations derived from
it and through pickling) and the functions' `allow_large=True` (for a path or dict) build it,
as the command line's `--allow-large`; Ctrl-C stops the build with KeyboardInterrupt. The
"did you mean" of an unknown key is the library's, the same words as the command line's."""

import os
import pickle
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import vibrotribo as vt

# The band: 100 000 harmonics over 117 244 intervals, about 1.2e10 evaluations (minutes).
LARGE = dict(
    excitation__kind="random",
    excitation__rms_acceleration=1.0,
    excitation__f_low_hz=0.001,
    excitation__f_high_hz=5000,
    excitation__duration_s=20,
    run__periods=4,
    run__transient_periods=2,
)
LARGE_DICT = {
    "excitation": {"kind": "random", "rms_acceleration": 1.0, "f_low_hz": 0.001, "f_high_hz": 5000,
                   "duration_s": 20},
    "run": {"periods": 4, "transient_periods": 2},
}


def test_a_build_past_the_limit_is_refused_naming_its_size_and_the_way_to_allow_it():
    with pytest.raises(ValueError, match=r"100000 harmonics over 117244 intervals.*allow_large=True"):
        vt.Config(**LARGE)
    # The functions read a dict within the same limit, and within theirs once they allow it.
    with pytest.raises(ValueError, match=r"100000 harmonics.*allow_large=True"):
        vt.lyapunov(LARGE_DICT)
    with pytest.raises(ValueError, match=r"100000 harmonics.*allow_large=True"):
        vt.simulate(LARGE_DICT)


def test_allow_large_is_kept_by_derived_and_pickled_configurations():
    c = vt.Config(allow_large=True, run__periods=30)
    assert c.allow_large and not vt.Config().allow_large
    for derived in (c.with_(run__transient_periods=10), c.replace(amplitude=0.05), c.without("run.periods"),
                    pickle.loads(pickle.dumps(c)), vt.Config(c)):
        assert derived.allow_large, derived
    assert pickle.loads(pickle.dumps(c)) == c
    assert vt.Config.from_toml("[run]\nperiods = 30\n", allow_large=True).allow_large
    # allow_large is not a key: it does not change the settings.
    assert c == vt.Config(run__periods=30) and hash(c) == hash(vt.Config(run__periods=30))


CHILD = textwrap.dedent(
    """
    import signal, sys, time
    import vibrotribo as vt
    signal.signal(signal.SIGINT, signal.default_int_handler)
    LARGE = {large!r}
    print("start", flush=True)
    try:
        {call}
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(0)
    except Exception as e:
        print("error", type(e).__name__, e, flush=True)
        sys.exit(2)
    print("built", flush=True)
    sys.exit(1)
    """
)


@pytest.mark.parametrize(
    "call",
    [
        "vt.Config(**{k.replace('.', '__'): v for k, v in LARGE.items()}, allow_large=True)",
        "vt.lyapunov(LARGE_DICT, allow_large=True)",
    ],
)
def test_an_allowed_large_build_runs_and_ctrl_c_stops_it(call):
    large = {k: v for k, v in LARGE.items()}
    source = CHILD.format(large=large, call=call).replace(
        "LARGE = ", f"LARGE_DICT = {LARGE_DICT!r}\nLARGE = "
    )
    p = subprocess.Popen([sys.executable, "-c", source], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.5)  # the build takes minutes: well inside it
        os.kill(p.pid, signal.SIGINT)
        line = p.stdout.readline().strip()
        p.wait(timeout=120)  # a bound against a hang, not a timing claim
    finally:
        if p.poll() is None:
            p.kill()
    # Refused, the child would have printed "error" at once; finished, "built".
    assert line == "interrupted", line
    assert p.returncode == 0


@pytest.mark.parametrize(
    "typo,first",
    [
        ("excitation.amplitdue", "excitation.amplitude"),
        ("omega_ratoi", "omega_ratio"),
        ("run.period", "run.periods"),
        ("electrical.atol", "electrical.atol_voltage"),
        ("stiffnes", "oscillator.stiffness"),
    ],
)
def test_did_you_mean_ranks_the_meant_key_first_as_the_command_line_does(cli, typo, first):
    with pytest.raises(KeyError) as e:
        vt.Config()[typo]
    message = str(e.value)
    hint = message.split("did you mean ")[1].split("?")[0]
    assert hint.startswith(f"`{first}`"), message
    p = subprocess.run([str(cli), "simulate", "--set", f"{typo}=1"], capture_output=True, text=True)
    assert p.returncode != 0
    assert f"did you mean {hint}?" in p.stderr, p.stderr
