"""Errors in a distributed run: never leave a rank waiting in a collective call.

Two mechanisms:

- :func:`collective` runs a step on every rank and exchanges an ok/failed flag afterwards; if
  any rank failed, every rank raises (the failing rank its own error; the others the same
  :class:`~femkit.errors.InputError` message when the fault is the input, else
  :class:`~femkit.errors.RankFailureError`), so input errors end all ranks cleanly (exit 2).
  It is used around steps that contain no collective call of their own (reading/generating
  the mesh on rank 0, evaluating the user's expressions).
- :func:`abort_on_error` is the last resort around a whole run: an exception escaping on one
  rank prints one line and calls ``MPI_Abort`` on the communicator, which ends every rank
  (the others may be blocked inside PETSc waiting for the failed one). Errors raised by
  :func:`collective`/:func:`from_root` (marked ``collective``) are on every rank already and
  pass through, so each rank ends normally with the same exit code.
"""

from __future__ import annotations

import sys
from contextlib import contextmanager

from ...errors import FemkitError, InputError, RankFailureError


def _reraise(comm, exc: BaseException | None):
    failures = comm.allgather(None if exc is None else (type(exc).__name__, str(exc),
                                                        isinstance(exc, InputError)))
    bad = [(r, f) for r, f in enumerate(failures) if f is not None]
    if not bad:
        return
    if exc is None:
        rank, (_, message, is_input) = bad[0]
        exc = InputError(message) if is_input else RankFailureError(rank, message)
    exc.collective = True  # raised on every rank: abort_on_error lets it end the run cleanly
    raise exc


def collective(comm, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` on every rank of the mpi4py ``comm``; a failure on any rank is
    raised on all ranks (see the module docstring)."""
    try:
        out = fn(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001  (re-raised on every rank)
        _reraise(comm, exc)
        raise
    _reraise(comm, None)
    return out


def from_root(comm, fn, *args, **kwargs):
    """``fn`` evaluated on rank 0 only and its result broadcast; an error on rank 0 is raised
    on every rank."""
    result = None
    if comm.Get_rank() == 0:
        try:
            result = ("ok", fn(*args, **kwargs))
        except Exception as exc:  # noqa: BLE001
            result = ("error", exc)
    status, value = comm.bcast(result, root=0)
    if status == "error":
        if comm.Get_rank() != 0 and not isinstance(value, FemkitError):
            value = RankFailureError(0, str(value))
        value.collective = True
        raise value
    return value


@contextmanager
def abort_on_error(comm, *, stream=None):
    """Around a whole distributed run: an exception on one rank (with more than one rank)
    prints ``femkit: error: ...`` and aborts the communicator (exit code 2 for input errors,
    1 otherwise), so no rank is left hanging."""
    try:
        yield
    except SystemExit:
        raise
    except BaseException as exc:  # noqa: BLE001
        if comm.Get_size() == 1 or getattr(exc, "collective", False):
            raise  # every rank raises it: each ends normally (the CLI prints on rank 0)
        code = 2 if isinstance(exc, InputError) else 1
        if not isinstance(exc, RankFailureError) or comm.Get_rank() == 0:
            print(f"femkit: error: rank {comm.Get_rank()}: {exc}", file=stream or sys.stderr,
                  flush=True)
        comm.Abort(code)
