"""Send a signal to a femkit process once it has announced (a line on stderr) that it is inside
the work under test; time how long it takes to exit."""

import subprocess
import sys
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


#: ``python -c SPY_DRIVER module:attr.path femkit-args...``: the command line as the console
#: script runs it, with ``attr.path`` of ``module`` replaced by a spy that prints ``READY`` on
#: stderr at its first call, so a test signals inside that piece of work.
SPY_DRIVER = r"""
import importlib, sys
target, argv = sys.argv[1], sys.argv[2:]
module, path = target.split(":")
owner = importlib.import_module(module)
*owners, name = path.split(".")
for o in owners:
    owner = getattr(owner, o)
real = getattr(owner, name)
seen = []

def spy(*args, **kwargs):
    if not seen:
        seen.append(1)
        print("READY", file=sys.stderr, flush=True)
    return real(*args, **kwargs)

setattr(owner, name, spy)
from femkit.cli import entry
sys.argv = ["femkit", *argv]
entry()
"""


def signal_inside(target: str, argv: list[str], sig, **kwargs) -> tuple[int, float, str]:
    """:func:`signal_when_ready` with :data:`SPY_DRIVER`: signal once ``target`` (``module:attr``)
    has started, under ``femkit *argv``."""
    return signal_when_ready(SPY_DRIVER, [target, *argv], "READY", sig, **kwargs)
