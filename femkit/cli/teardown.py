"""How the ``femkit`` process ends: by ``os._exit`` after what a normal exit does that matters
(:func:`exit_now`), except where a library must be finalised by the interpreter's own exit
(:data:`FINALIZE_AT_EXIT`); why: :func:`femkit.cli.entry`."""

from __future__ import annotations

import sys

#: modules whose libraries must be finalised by the interpreter's own exit (C-level exit
#: handlers that ``os._exit`` skips): mpi4py's ``MPI_Finalize`` (without it ``mpirun`` reports
#: the rank as exiting improperly and fails the run) and PETSc's ``PetscFinalize``.
FINALIZE_AT_EXIT = ("mpi4py", "petsc4py")


def exit_now(code: int, *, clean: bool = True) -> None:
    """End the process with ``code`` by ``os._exit``; ``clean``: first join the non-daemon
    threads and run the ``atexit`` handlers (what a normal exit does before its teardown)."""
    import os

    if clean:
        import threading

        shutdown = getattr(threading, "_shutdown", None)  # joins non-daemon threads
        if shutdown is not None:
            shutdown()
        import atexit

        atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (``femkit solve ... | head``)
            pass
    os._exit(code)
