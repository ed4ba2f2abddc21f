"""A writer thread: output jobs run beside the computation, not on its critical path.

:class:`BackgroundWriter` runs the jobs given to :meth:`~BackgroundWriter.submit` in order, in
one daemon thread, through a bounded queue: the producer (a simulation loop handing over each
recorded frame) waits only when the writer is ``depth`` jobs behind, so memory stays bounded
and a slow disk slows the run instead of filling the memory. A job's arguments must not be
modified after submission (the caller hands over copies).

Errors: the first exception of a job stops the writer (later jobs are dropped) and is raised
in the producer's thread at its next :meth:`~BackgroundWriter.submit` or at
:meth:`~BackgroundWriter.close`: a :class:`~femkit.errors.FemkitError` as it is, anything else
as a :class:`~femkit.errors.FemkitError` naming it. Leaving the ``with`` block on an exception
cancels the queued jobs and waits for the one running, so the caller can then remove what was
written (an atomic output directory) without a thread still writing into it.

Waiting is done in short slices, so a signal handler of the main thread (a stop request,
:mod:`femkit.interrupt`) runs at once while the producer waits.

>>> out = []
>>> with BackgroundWriter(depth=2) as w:
...     for k in range(5):
...         w.submit(out.append, k)
...     w.close()
5
>>> out
[0, 1, 2, 3, 4]
"""

from __future__ import annotations

import queue
import threading
from typing import Any, Callable

from ..errors import FemkitError

__all__ = ["BackgroundWriter"]

_POLL = 0.05  # seconds: how long a wait lasts before the producer looks again (signals run)
_CANCEL_WAIT = 10.0  # seconds: at most this long for the running job after a cancellation


class BackgroundWriter:
    """Run output jobs in order in one writer thread (module docstring).

    Parameters
    ----------
    depth : int
        Jobs that may wait in the queue; :meth:`submit` blocks beyond that.
    name : str
        The thread's name (shown by debuggers and in error messages).
    background : bool
        False runs every job at once in the caller's thread (the synchronous writer: the same
        jobs, the same files; for comparison and for callers without threads).
    """

    def __init__(self, depth: int = 8, name: str = "femkit writer", background: bool = True):
        self.name = name
        self.background = bool(background)
        self.done = 0                       # jobs completed
        self._queue: queue.Queue = queue.Queue(maxsize=max(1, int(depth)))
        self._error: BaseException | None = None
        self._cancel = threading.Event()
        self._thread: threading.Thread | None = None
        if self.background:
            self._thread = threading.Thread(target=self._work, name=name, daemon=True)
            self._thread.start()

    # ------------------------------------------------------------------ producer side
    def submit(self, fn: Callable[..., Any], *args: Any) -> None:
        """Queue ``fn(*args)`` (run it now when not in the background).

        Raises
        ------
        FemkitError
            An earlier job failed (its reason), or the writer was closed.
        """
        self._raise_error()
        if not self.background:
            self._run(fn, args)
            self._raise_error()
            return
        if self._thread is None or self._cancel.is_set():
            raise FemkitError(f"{self.name}: closed, no more jobs accepted")
        while True:
            try:
                self._queue.put((fn, args), timeout=_POLL)
                return
            except queue.Full:
                self._raise_error()

    def close(self, stop: Callable[[], bool] | None = None) -> int:
        """Wait until every queued job has run; return how many jobs ran in all.

        ``stop``: checked while waiting; once true, the jobs not yet started are dropped and
        only the running one is finished (e.g. a stop request while frames are being written:
        those written so far are kept). Raises the first job's error (see :meth:`submit`).
        """
        if self._thread is not None:
            self._queue_end()
            while self._thread.is_alive():
                if stop is not None and stop():
                    self._cancel.set()
                self._thread.join(_POLL)
            self._thread = None
        self._raise_error()
        return self.done

    def cancel(self) -> None:
        """Drop the jobs not yet started and wait (bounded) for the running one."""
        self._cancel.set()
        if self._thread is not None:
            self._queue_end()
            self._thread.join(_CANCEL_WAIT)
            self._thread = None

    def __enter__(self) -> "BackgroundWriter":
        return self

    def __exit__(self, kind, value, tb) -> None:
        if kind is not None:
            self.cancel()
        else:
            self.close()

    # ------------------------------------------------------------------ writer side
    def _queue_end(self) -> None:
        """Put the end marker, waiting in slices for room (the writer drains or is cancelled)."""
        while self._thread is not None and self._thread.is_alive():
            try:
                self._queue.put(None, timeout=_POLL)
                return
            except queue.Full:
                continue

    def _work(self) -> None:
        while True:
            job = self._queue.get()
            if job is None:
                return
            if self._cancel.is_set() or self._error is not None:
                continue  # drain without running, until the end marker
            self._run(*job)

    def _run(self, fn, args) -> None:
        try:
            fn(*args)
            self.done += 1
        except BaseException as exc:  # relayed to the producer, never lost in the thread
            if self._error is None:
                self._error = exc

    def _raise_error(self) -> None:
        exc = self._error
        if exc is None:
            return
        self._cancel.set()
        if isinstance(exc, FemkitError):
            raise exc
        raise FemkitError(f"{self.name} failed: {type(exc).__name__}: {exc}") from exc
