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
