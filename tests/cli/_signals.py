"""Signal a femkit process inside the work under test; time how long it takes to exit.

:func:`signal_inside` makes the run signal itself a set time after the work under test began
(no race with the test's own scheduling on a loaded machine); :func:`signal_when_ready` sends
the signal from the test once the process announces (a line on stderr) that it is inside."""

import os
import subprocess
import sys
import tempfile
import time


def signal_when_ready(driver: str, args: list[str], ready: str, sig, *, cwd=None,
                      settle: float = 0.3) -> tuple[int, float, str]:
    """Run ``python -c driver *args``; after its first stderr line equals ``ready`` wait
    ``settle`` seconds, send ``sig``; return (exit code, seconds from signal to exit, stderr)."""
    proc = subprocess.Popen([sys.executable, "-c", driver, *args], cwd=cwd,
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    try:
        line = proc.stderr.readline()
        assert line.strip() == ready, line
        time.sleep(settle)
        assert proc.poll() is None, f"finished before the signal: make the work under test longer"
        t0 = time.perf_counter()
        proc.send_signal(sig)
        proc.wait(timeout=60)
        elapsed = time.perf_counter() - t0
        return proc.returncode, elapsed, proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


#: ``python -c SPY_DRIVER module:attr.path signum settle stamp femkit-args...``: the command line
#: as the console script runs it, with ``attr.path`` of ``module`` replaced by a spy whose first
#: call starts a timer: ``settle`` seconds later (by the run's own clock, whatever else the
#: machine is doing) the process sends itself ``signum`` and writes the monotonic time it was due
#: to the file ``stamp``, so the signal lands inside that piece of work however late the test's
#: own process is scheduled.
SPY_DRIVER = r"""
import importlib, os, sys, threading, time
target, signum, settle, stamp, argv = (sys.argv[1], int(sys.argv[2]), float(sys.argv[3]),
                                       sys.argv[4], sys.argv[5:])
module, path = target.split(":")
owner = importlib.import_module(module)
*owners, name = path.split(".")
for o in owners:
    owner = getattr(owner, o)
real = getattr(owner, name)
started = []

def fire(due):
    # the time the signal was due: a kernel holding the GIL delays this thread's kill exactly
    # as long as it delays the handler of a signal sent from outside, so the wait counts
    with open(stamp, "w") as f:
        f.write(repr(due))
    os.kill(os.getpid(), signum)

def spy(*args, **kwargs):
    if not started:
        started.append(1)
        timer = threading.Timer(settle, fire, (time.monotonic() + settle,))
        timer.daemon = True
        timer.start()
    return real(*args, **kwargs)

setattr(owner, name, spy)
from femkit.cli import entry
sys.argv = ["femkit", *argv]
entry()
"""


def signal_inside(target: str, argv: list[str], sig, *, cwd=None,
                  settle: float = 0.3) -> tuple[int, float, str]:
    """Run ``femkit *argv`` with :data:`SPY_DRIVER`: ``settle`` seconds after ``target``
    (``module:attr``) has started, the run sends itself ``sig``. Returns (exit code, seconds
    from the signal to the exit, stderr)."""
    with tempfile.TemporaryDirectory() as scratch:
        stamp = os.path.join(scratch, "signalled")
        proc = subprocess.Popen([sys.executable, "-c", SPY_DRIVER, target, str(int(sig)),
                                 str(settle), stamp, *argv], cwd=cwd, stderr=subprocess.PIPE,
                                stdout=subprocess.DEVNULL, text=True)
        try:
            _, err = proc.communicate(timeout=600)
            exited = time.monotonic()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        assert os.path.exists(stamp), (f"finished before the signal (exit {proc.returncode}): "
                                       f"make the work under test longer\n{err[-2000:]}")
        with open(stamp) as f:
            signalled = float(f.read())
    return proc.returncode, exited - signalled, err


def slack(idle: float = 3.0) -> float:
    """Seconds a stop may take from the signal to the exit: ``idle`` (the target is 1 s) on an
    idle machine, scaled by the load per core now (the signal is answered by a process that
    shares the cores: a stop that waited for the work to end would take the rest of the run,
    tens of seconds). Read when asserting, not when the tests are collected (the load of a
    test run changes as it goes)."""
    return idle * max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))
