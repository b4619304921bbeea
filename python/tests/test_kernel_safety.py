"""Safe in a kernel: sizes are refused before anything is allocated (MemoryError or
ValueError naming the argument, the command line's limits), a bad count is a ValueError
naming its argument, and Ctrl-C during a continuation is a KeyboardInterrupt (no panic)."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import vibrotribo as vt


def test_a_run_too_large_for_memory_is_refused_before_it_starts():
    # 200 000 periods × 100 samples per period × 16 numbers × 8 bytes ≈ 2.4 GiB of samples
    # alone; with 400 samples per period ≈ 9.5 GiB: above the 4 GiB limit.
    config = vt.Config(run__periods=200000, run__samples_per_period=400)
    with pytest.raises(MemoryError, match=r"run.periods = 200000.*allow_large=True"):
        vt.simulate(config)
    # Without samples the same run keeps only its per-period statistics (about 37 MB).
    assert vt._vibrotribo.MAX_MEMORY_BYTES == 4 * 1024**3


def test_grids_above_the_limit_name_their_argument():
    with pytest.raises(ValueError, match=r"x_values × y_values asks for 1\.000e\+?0?8"):
        vt.map(None, "omega_ratio", [0.5] * 10000, "gap_ratio", [1.0] * 10000)
    with pytest.raises(ValueError, match="grid asks for"):
        vt.basins(None, "run.initial_positions[0]", 0, 0.01, "run.initial_velocities[0]", 0, 1, (10**4, 10**4))


@pytest.mark.parametrize(
    "call,name",
    [
        (lambda: vt.sweep(None, "omega_ratio", [0.6], transient=-5), "transient"),
        (lambda: vt.map(None, "omega_ratio", [0.6], "gap_ratio", [1.0], recorded=-1), "recorded"),
        (lambda: vt.periodic(None, transient=-5), "transient"),
        (lambda: vt.continue_(None, "omega_ratio", 0.7, 0.8, max_points=0), "max_points"),
        (lambda: vt.lyapunov(None, periods=0), "periods"),
        (lambda: vt.load_sweep(None, steps=-3), "steps"),
    ],
)
def test_negative_counts_are_value_errors_naming_the_argument(call, name):
    with pytest.raises(ValueError, match=name):
        call()


CHILD = textwrap.dedent(
    """
    import signal, sys
    import vibrotribo as vt
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print("start", flush=True)
    try:
        # Continuations one after the other: the signal arrives during one of them (during
        # the continuation itself or the power along its branches), whatever the speed.
        while True:
            vt.continue_(vt.Config(), "omega_ratio", 0.7, 1.0)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(0)
    except BaseException as e:
        print("other", type(e).__name__, e, flush=True)
        sys.exit(2)
    print("finished", flush=True)
    sys.exit(1)
    """
)


def test_sigint_during_continue_is_a_keyboard_interrupt():
    p = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(2.0)
        os.kill(p.pid, signal.SIGINT)
        out = p.stdout.read()
        p.wait(timeout=600)
    finally:
        if p.poll() is None:
            p.kill()
    assert out.split()[:1] == ["interrupted"], out
    assert p.returncode == 0
