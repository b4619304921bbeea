"""Ctrl-C during `continue_` and `periodic`: SIGINT to a child process mid-computation raises
KeyboardInterrupt promptly (the library polls a cancel hook at every continuation step,
Newton iteration and through the transient), never a PanicException, and the process goes
on normally afterwards."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

CHILD = textwrap.dedent(
    """
    import signal, sys, time
    import vibrotribo as vt
    signal.signal(signal.SIGINT, signal.default_int_handler)
    what = sys.argv[1]
    print("start", flush=True)
    try:
        if what == "continue":
            # A long branch: far more points than a few seconds allow.
            vt.continue_(vt.Config(), "omega_ratio", 0.7, 3.0, transient=50,
                         max_points=100000, initial_step=1e-5, max_step=1e-5,
                         mechanics_only=True)
        else:
            # A transient of hours before the shooting.
            vt.periodic(vt.Config(), transient=10**8, mechanics_only=True)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
        # The interpreter is healthy: a short computation still runs.
        o = vt.periodic(vt.Config(), transient=50, mechanics_only=True)
        print("after", o.period, flush=True)
        sys.exit(0)
    except BaseException as e:
        print("raised", type(e).__name__, flush=True)
        sys.exit(2)
    print("finished", flush=True)
    sys.exit(1)
    """
)


@pytest.mark.parametrize("what", ["continue", "periodic"])
def test_sigint_stops_continuation_and_shooting_with_keyboard_interrupt(what):
    p = subprocess.Popen(
        [sys.executable, "-c", CHILD, what], stdout=subprocess.PIPE, text=True
    )
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(2.0)  # well inside the computation
        sent = time.monotonic()
        os.kill(p.pid, signal.SIGINT)
        line = p.stdout.readline().split()
        after = p.stdout.readline().split()
        p.wait(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert line[:1] == ["interrupted"], line
    assert after == ["after", "1"], after
    assert p.returncode == 0
    delay = float(line[1]) - sent
    # Polled every step: well under the length of the computation (minutes to hours); the
    # bound leaves room for a loaded machine.
    assert delay < 2.0, f"KeyboardInterrupt {delay:.3f} s after SIGINT"
