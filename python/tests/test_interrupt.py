"""Ctrl-C: SIGINT to a process running a long `simulate` (minutes of work) raises
KeyboardInterrupt within a second; the GIL is released meanwhile (another thread runs)."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import vibrotribo as vt

CHILD = textwrap.dedent(
    """
    import signal, sys, time
    import vibrotribo as vt
    # Python's own Ctrl-C handler, whatever the disposition inherited (a CI job may ignore SIGINT).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    config = vt.Config(run__periods=10**8)  # about an hour of work
    print("start", flush=True)
    try:
        vt.simulate(config, samples=False, allow_large=True)  # interrupted long before it grows
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
        sys.exit(0)
    print("finished", flush=True)
    sys.exit(1)
    """
)


def test_sigint_raises_keyboard_interrupt_within_a_second():
    p = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.0)  # well inside the run
        sent = time.monotonic()
        os.kill(p.pid, signal.SIGINT)
        line = p.stdout.readline().split()
        p.wait(timeout=30)
    finally:
        if p.poll() is None:
            p.kill()
    assert line[:1] == ["interrupted"], line
    delay = float(line[1]) - sent
    assert p.returncode == 0
    assert delay < 1.0, f"KeyboardInterrupt {delay:.3f} s after SIGINT"


def test_the_gil_is_released_while_computing():
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        started = time.monotonic()
        vt.simulate(vt.Config(run__periods=20000), samples=False, mechanics_only=True)
        ended = time.monotonic()
    finally:
        done.set()
        t.join()
    during = [x for x in ticks if started < x < ended]
    # With the GIL held the other thread could not run at all during the run.
    assert len(during) > 10, f"{len(during)} ticks in {ended - started:.3f} s"


RESPONSE_CHILD = textwrap.dedent(
    """
    import signal, sys
    import vibrotribo as vt
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print("start", flush=True)
    try:
        # Two sweeps of 2000 values: minutes of work.
        vt.response(vt.Config(), vt.grid(0.5, 1.0, 2000), recorded=200)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(0)
    print("finished", flush=True)
    sys.exit(1)
    """
)


def test_sigint_stops_a_frequency_response():
    """Both sweeps (one on a thread of its own) stop at their next value and the call raises
    KeyboardInterrupt."""
    p = subprocess.Popen([sys.executable, "-c", RESPONSE_CHILD], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.0)
        os.kill(p.pid, signal.SIGINT)
        line = p.stdout.readline().strip()
        p.wait(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert line == "interrupted", line
    assert p.returncode == 0
