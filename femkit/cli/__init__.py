"""The ``femkit`` command line: ``femkit solve CASE``, ``femkit check CASE``, ``femkit study``,
``femkit list``, ``femkit warmup``, ``femkit view RUN_DIR``.

Modules: :mod:`~femkit.cli.parser` (argparse: every subcommand's flags and help, ``--set``),
:mod:`~femkit.cli.commands` (what each subcommand does), :mod:`~femkit.cli.messages` (exit codes,
one-line errors and warnings), :mod:`~femkit.cli.startup` (imports deferred at start-up),
:mod:`~femkit.cli.teardown` (the process's exit), :mod:`~femkit.cli.bytecode` (``femkit warmup``'s
``.pyc`` writer); here :func:`main` (one command) and :func:`entry` (the process).

These modules import only the standard library at module level, so ``femkit --help`` is
instant; each subcommand imports what it needs when it runs.

Exit codes (every subcommand):
  0  success
  1  the computation ran but failed its goal (solver did not converge; a cross-check
     exceeded its tolerance; a solver/integrator error)
  2  bad input (case file, expression, name, mesh), or a predicted cost above a budget
     (memory, time, steps, output; --force overrides); one line on stderr, nothing written
  130/143  stopped by SIGINT/SIGTERM: what was computed is written, marked interrupted: true

Adding a subcommand: write ``_add_<name>(sub)`` in :mod:`~femkit.cli.parser` that declares its
parser and sets ``handler`` (or ``func``; a function ``args -> int``, e.g. in
:mod:`~femkit.cli.commands`), then append it to :data:`~femkit.cli.parser.SUBCOMMANDS`.
"""

from __future__ import annotations

import sys
from typing import Sequence

from .messages import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, mpi_rank, one_line, one_line_warning
from .parser import SUBCOMMANDS, build_parser, parse_sets
from .startup import DEFERRED_IMPORTS, defer_unused_imports
from .teardown import FINALIZE_AT_EXIT, exit_now

__all__ = ["main", "entry", "build_parser", "parse_sets", "SUBCOMMANDS",
           "DEFERRED_IMPORTS", "EXIT_OK", "EXIT_FAILED", "EXIT_BAD_INPUT"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``femkit`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    from ..errors import FemkitError, InputError
    from ..interrupt import Interrupted

    handler = getattr(args, "handler", None) or getattr(args, "func")  # func: femkit.study.cli style
    from ..allocator import from_environment

    from_environment()  # FEMKIT_RETURN_MEMORY=1: freed arrays go back to the system at once
    speaks = mpi_rank() == 0  # under mpirun every rank raises the same error: rank 0 says it
    import warnings

    shown = warnings.showwarning
    warnings.showwarning = one_line_warning
    try:
        args.overrides = parse_sets(getattr(args, "sets", ()))
        return int(handler(args))
    except InputError as exc:
        if speaks:
            print(f"femkit: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except FemkitError as exc:
        if speaks:
            print(f"femkit: failed: {one_line(exc)}", file=sys.stderr)
        return EXIT_FAILED
    except Interrupted as exc:  # stopped between stages: nothing was written
        print(f"femkit: {exc}; nothing written", file=sys.stderr)
        return 128 + int(exc.flag.signum or 2)
    except KeyboardInterrupt:
        print("femkit: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.showwarning = shown


def entry() -> None:
    """The ``femkit`` console script and ``python -m femkit``: :func:`main`, then the exit.

    The process ends with :func:`~femkit.cli.teardown.exit_now` rather than the interpreter's own teardown, which
    clears a thousand modules (numba, llvmlite, scipy) and their objects one by one: 0.25-0.4 s
    after the results of a solve are written, doing nothing the user can see. What that teardown
    does that matters is done first, in CPython's order: the non-daemon threads are joined, the
    ``atexit`` handlers run, and stdout and stderr are flushed. What the run keeps is already
    written and closed (atomic writes) when :func:`main` returns. Under a profiler or a tracer
    (``python -m cProfile -o p.out -m femkit.cli ...``, coverage, a debugger), which write their
    results after the command returns, the exit is the interpreter's own.

    After a stop request (exit 130 / 143) the process ends at once, its output flushed but no
    thread joined: the request may have abandoned compiled work in a thread (gmsh's mesher:
    :func:`femkit.interrupt.run_interruptible`) or raised out of a C library's call
    (:func:`femkit.interrupt.raising`), and waiting for it, or the library's destructors run on
    its half-done state, would hang or crash (exit -11 instead of 130).
    """
    defer_unused_imports()
    code = main()
    from ..interrupt import abandoned_work

    stopped = code in (130, 143) or abandoned_work()
    if not stopped and (sys.getprofile() is not None or sys.gettrace() is not None):
        sys.exit(code)  # under a profiler or a debugger, which write their results after us
    if not stopped and any(m in sys.modules for m in FINALIZE_AT_EXIT):
        sys.exit(code)  # MPI / PETSc finalise in the interpreter's own exit (mpirun needs it)
    exit_now(code, clean=not stopped)
