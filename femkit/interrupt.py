"""Stop cleanly on SIGINT / SIGTERM: a flag the long loops check between units of work.

:func:`stop_on_signals` installs handlers that only set a :class:`StopFlag`; a loop (the time
steps of :func:`femkit.dynamics.simulate.simulate`, the jobs of a study) checks the flag
between steps, stops, and returns what it computed so far, which the caller writes (frames,
energy, ``result.json`` with ``interrupted: true``) before exiting with :func:`exit_code`
(``128 + signal number``: 130 for SIGINT, 143 for SIGTERM). A second SIGINT while the flag is
already set raises :class:`KeyboardInterrupt` at once, for a user who does not want to wait.

An iterative linear solve stops the same way through its per-iteration callback
(:func:`stopping_callback`): the callback raises :class:`Interrupted` carrying the last
iterate, which the caller may write as a partial (not converged) result. A direct
factorisation runs in compiled code and cannot be stopped midway: the flag is seen when it
returns.

Work that keeps nothing partial (a study's sweep, whose report appears only when complete;
a Poisson run's assembly) runs inside :func:`raising`: there the signal handler itself raises
:class:`Interrupted` at once, wherever the main thread is (between two numpy calls, inside an
integrator's iteration), instead of waiting for the next check. A study stopped so keeps its
earlier report untouched; a Poisson run stopped so writes nothing.

A **second Ctrl-C** while the first is being honoured (e.g. frames still being written) raises
:class:`KeyboardInterrupt` at once: the command exits 130 at once and what the first would have
written may be incomplete or missing (never a half-written file under its final name: outputs
are written atomically).

Handlers are installed only in the main thread (Python's rule); elsewhere the flag works but
never fires by itself. The previous handlers are restored on exit.

>>> flag = StopFlag()
>>> bool(flag), flag.request(15), bool(flag), flag.name, exit_code(flag)
(False, None, True, 'SIGTERM', 143)
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from typing import Iterator

__all__ = ["StopFlag", "stop_on_signals", "exit_code", "Interrupted", "stopping_callback",
           "active_flag", "raising", "checkpoint", "run_interruptible", "abandoned_work"]


class StopFlag:
    """Set when a stop was requested; ``signum`` says by which signal (``None``: not set)."""

    def __init__(self) -> None:
        self.signum: int | None = None
        self.raising: list[str] = []  # the open raising() blocks, innermost last
        self.deferred = False  # a raise put off until numba's machinery has returned

    def request(self, signum: int = signal.SIGINT) -> None:
        """Ask the running loop to stop after its current unit of work."""
        self.signum = int(signum)

    def __bool__(self) -> bool:
        return self.signum is not None

    def __call__(self) -> bool:  # usable as a ``stop()`` callable
        return self.signum is not None

    @property
    def name(self) -> str | None:
        """``"SIGINT"``, ``"SIGTERM"`` ... (``None`` when not set)."""
        if self.signum is None:
            return None
        try:
            return signal.Signals(self.signum).name
        except ValueError:
            return f"signal {self.signum}"


def exit_code(flag: StopFlag) -> int:
    """The shell's exit code for a run stopped by ``flag``'s signal: ``128 + signum``."""
    return 128 + int(flag.signum or signal.SIGINT)


_ACTIVE: list[StopFlag] = []
_WORKERS: list[threading.Event] = []  # "finished" events of run_interruptible's workers


def active_flag() -> StopFlag | None:
    """The flag of the innermost :func:`stop_on_signals` block now running (None outside any):
    how loops deep inside a run (a study's sweep) see a stop request without it being passed."""
    return _ACTIVE[-1] if _ACTIVE else None


@contextlib.contextmanager
def stop_on_signals(signals=(signal.SIGINT, signal.SIGTERM)) -> Iterator[StopFlag]:
    """Within the block, the given signals set the yielded :class:`StopFlag` instead of killing."""
    flag = StopFlag()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    _ACTIVE.append(flag)

    def handler(signum, frame):
        redelivered, flag.deferred = flag.deferred, False
        if flag and signum == signal.SIGINT and not redelivered:
            raise KeyboardInterrupt
        flag.request(signum)
        if flag.raising:  # inside raising(): stop the work where it is
            if _inside_numba(frame):  # not inside numba's loader: deliver again shortly
                flag.deferred = True
                threading.Timer(0.02, os.kill, (os.getpid(), signum)).start()
                return
            raise Interrupted(flag, where=f"during {flag.raising[-1]}")

    previous = {}
    for s in signals:
        previous[s] = signal.signal(s, handler)
    try:
        yield flag
    finally:
        _ACTIVE.remove(flag)
        for s, h in previous.items():
            signal.signal(s, h)


def _inside_numba(frame) -> bool:
    """Whether the interrupted Python code is numba's own (compiling a kernel, or loading it
    from its cache): an exception raised there from a signal handler leaves numba's state
    half-built and the process crashes later (SIGSEGV instead of exit 130)."""
    while frame is not None:
        parts = frame.f_code.co_filename.replace("\\", "/").split("/")
        if "numba" in parts or "llvmlite" in parts:
            return True
        frame = frame.f_back
    return False


class Interrupted(Exception):
    """A run stopped on request; ``x`` is the last iterate (iterative solves) or ``None``,
    ``iteration`` how many iterations were done, ``stage`` where a staged run stopped,
    ``flag`` the :class:`StopFlag` that fired."""

    def __init__(self, flag: StopFlag, x=None, iteration: int = 0, stage: str = "", where: str = ""):
        self.flag, self.x, self.iteration, self.stage = flag, x, iteration, stage
        where = where or (f"after the {stage} stage" if stage else f"at iteration {iteration}")
        super().__init__(f"interrupted by {flag.name or 'a stop request'} {where}")


@contextlib.contextmanager
def raising(what: str) -> Iterator[None]:
    """Within the block, a stop request raises :class:`Interrupted` (``during <what>``) at once,
    from the signal handler, wherever the main thread is; for work whose partial state is not
    kept (see the module docstring). Outside :func:`stop_on_signals`, or off the main thread, it
    does nothing. A stop requested before the block raises on entry.

    >>> with stop_on_signals() as flag:
    ...     try:
    ...         with raising("the sweep"):
    ...             signal.raise_signal(signal.SIGTERM)
    ...             print("not reached")
    ...     except Interrupted as exc:
    ...         print(exc)
    interrupted by SIGTERM during the sweep
    """
    flag = active_flag()
    if flag is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    checkpoint(f"before {what}")
    flag.raising.append(what)
    try:
        yield
    finally:
        flag.raising.pop()


def checkpoint(where: str = "") -> None:
    """Raise :class:`Interrupted` when a stop was requested (in the innermost
    :func:`stop_on_signals` block); nothing otherwise. For loops that keep nothing partial."""
    flag = active_flag()
    if flag:
        raise Interrupted(flag, where=where)


def stopping_callback(flag: StopFlag, callback=None):
    """A solver callback that raises :class:`Interrupted` (with the iterate) once ``flag`` is set.

    >>> import numpy as np, scipy.sparse as sp
    >>> from femkit.solvers import solve
    >>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(50, 50), format="csr")
    >>> flag = StopFlag()
    >>> def stop_at_5(x, count=[0]):
    ...     count[0] += 1
    ...     if count[0] == 5:
    ...         flag.request(15)
    >>> try:
    ...     solve(A, np.ones(50), method="cg", callback=stopping_callback(flag, stop_at_5))
    ... except Interrupted as exc:
    ...     print(exc, exc.x.shape)
    interrupted by SIGTERM at iteration 5 (50,)
    """
    count = [0]

    def cb(xk):
        count[0] += 1
        if callback is not None:
            callback(xk)
        if flag:
            raise Interrupted(flag, xk.copy(), count[0])

    return cb


def run_interruptible(fn, *args, what: str, on_abandon=None, poll: float = 0.05, **kwargs):
    """``fn(*args, **kwargs)``, answering a stop request within ``poll`` seconds even while ``fn``
    runs compiled code that never returns to Python (gmsh's mesher, a long factorisation).

    Outside a :func:`stop_on_signals` block, or off the main thread, ``fn`` is simply called.
    Inside one, ``fn`` runs in a daemon thread (the C library must release the GIL, as ctypes
    calls do) while the main thread waits in short slices, so the signal handler runs at once.
    When the flag is set, :class:`Interrupted` is raised ``during <what>`` and the worker is
    abandoned to end with the process; ``on_abandon()`` is called first, so the caller can skip
    clean-up that would race the worker (e.g. not finalise gmsh under its running mesher).

    >>> run_interruptible(sum, [1, 2, 3], what="adding")
    6
    """
    flag = active_flag()
    if flag is None or threading.current_thread() is not threading.main_thread():
        return fn(*args, **kwargs)
    if flag:
        raise Interrupted(flag, where=f"before {what}")
    box: dict = {}
    done = threading.Event()  # the worker's own "finished": see below

    def work():
        try:
            box["value"] = fn(*args, **kwargs)
        except BaseException as exc:  # relayed to the waiting thread
            box["error"] = exc
        finally:
            done.set()

    worker = threading.Thread(target=work, name=f"femkit {what}", daemon=True)
    _WORKERS.append(done)
    worker.start()
    # Wait on an Event, not Thread.join: a signal handler raising inside join() makes CPython
    # (3.11, bpo-45274's fix) release the worker's state lock and mark the *running* worker as
    # stopped, so is_alive() would lie and the caller would clean up under it (gmsh finalised
    # under its running mesher: SIGSEGV instead of exit 130).
    try:
        while not done.wait(poll):
            if flag:
                raise Interrupted(flag, where=f"during {what}")
    except BaseException:  # Interrupted, or KeyboardInterrupt from a second Ctrl-C
        if not done.is_set() and on_abandon is not None:
            on_abandon()
        raise
    if "error" in box:
        raise box["error"]
    return box.get("value")


def abandoned_work() -> bool:
    """Whether a stop request left a :func:`run_interruptible` worker running. The command line
    then ends the process with ``os._exit`` after flushing its output: a normal interpreter exit
    would run the C library's global destructors under its still-running thread (a crash)."""
    return any(not done.is_set() for done in _WORKERS)
