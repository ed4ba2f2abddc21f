"""The ``femkit`` command line: ``femkit solve CASE``, ``femkit check CASE``.

This module imports only the standard library at module level, so ``femkit --help`` is
instant; each subcommand imports what it needs when it runs.

Exit codes (every subcommand):
  0  success
  1  the computation ran but failed its goal (solver did not converge; a cross-check
     exceeded its tolerance; a solver/integrator error)
  2  bad input (case file, expression, name, mesh), or a predicted cost above a budget
     (memory, time, steps, output; --force overrides); one line on stderr, nothing written
  130/143  stopped by SIGINT/SIGTERM: what was computed is written, marked interrupted: true

Adding a subcommand: write ``_add_<name>(sub)`` that declares its parser and sets
``handler`` (or ``func``; a function ``args -> int``), then append it to :data:`SUBCOMMANDS`.
"""

from __future__ import annotations

import argparse
import sys
from typing import Callable, Sequence

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2

_EPILOG = """\
exit codes:
  0  success
  1  ran, but did not reach its goal (solver not converged, check out of tolerance)
  2  bad input (case file, --set value, expression, solver name, mesh), or a
     predicted cost above a budget (--force runs anyway); a one-line message on
     stderr and no output written
  130, 143  stopped by SIGINT / SIGTERM; what was computed is written (result.json
     with interrupted: true); a second Ctrl-C stops at once, the output may then
     be incomplete

examples:
  femkit solve cases/poisson_unit_square.yaml
  femkit solve cases/poisson_lshape.yaml --output runs/lshape --quiet
  femkit solve cases/poisson_unit_square.yaml --set mesh.h=0.02 --set solver.preconditioner=ic0
  femkit solve cases/poisson_unit_square.yaml --dry-run
  femkit check cases/poisson_unit_square.yaml
  femkit list solvers

Case-file reference: docs/case-files.md; command line: docs/cli.md.
"""

_CHECK_EPILOG = """\
exit codes (check writes no files):
  0  every row within its tolerance
  1  a row out of tolerance (the table says which)
  2  bad input (case file, --set value, not a Poisson case); one line on stderr
  130, 143  stopped by SIGINT / SIGTERM

examples:
  femkit check cases/poisson_unit_square.yaml
  femkit check cases/poisson_lshape.yaml --set mesh.h=0.05 --quiet
"""

_STUDY_EPILOG = """\
study kinds (the file's kind:):
{kinds}

exit codes:
  0  report written (runs that failed or went unstable are reported as data)
  2  bad input (study file, --set value, a case it names), or a predicted cost
     above a budget (--force runs anyway); one line on stderr, nothing written
  130, 143  stopped by SIGINT / SIGTERM: answered within a second, inside the
     current run; nothing new is written and an earlier report is kept as it was;
     a second Ctrl-C stops at once

examples:
  femkit study studies/poisson_convergence.yaml --quick
  femkit study studies/stress.yaml --output runs/stress
  femkit study studies/poisson_convergence.yaml --set levels.count=3 --dry-run

Study-file reference: docs/studies.md.
"""


def _study_epilog() -> str:
    """``femkit study --help``'s epilog: the study kinds read from the registry (plugins too)."""
    from .catalog import entries

    rows = entries("studies")
    width = max((len(n) for n, _ in rows), default=0)
    return _STUDY_EPILOG.format(kinds="\n".join(f"  {n.ljust(width)}  {d}" for n, d in rows))


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors exit with code 2 and one line (no usage dump)."""

    #: a function returning the epilog, called only when the help is shown (``femkit study``
    #: lists the registered kinds: importing them for every command would be slow)
    epilog_fn: Callable[[], str] | None = None

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(EXIT_BAD_INPUT, f"femkit: error: {message} (see '{self.prog} --help')\n")

    def format_help(self) -> str:
        if self.epilog_fn is not None:
            self.epilog = self.epilog_fn()
        return super().format_help()


# ----------------------------------------------------------------------------- solve

def _case_parser(sub, name: str, help: str, description: str, case_help: str, quiet_help: str,
                 handler: Callable, epilog: str = _EPILOG) -> argparse.ArgumentParser:
    """A subcommand taking one CASE file and ``--quiet`` (the shape of ``solve`` and ``check``)."""
    p = sub.add_parser(name, help=help, description=description, epilog=epilog,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case", metavar="CASE", help=case_help)
    p.add_argument("-q", "--quiet", action="store_true", help=quiet_help)
    _add_set_flag(p)
    p.set_defaults(handler=handler)
    return p


# ----------------------------------------------------------------------------- --set

def _add_set_flag(p: argparse.ArgumentParser) -> None:
    """``--set KEY=VALUE`` (repeatable), shared by ``solve``, ``check`` and ``study``."""
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="change one key of the file before it is validated, e.g. --set mesh.h=0.02 "
                        "or --set solver.method=direct (dotted path; VALUE read as in a file: 0.02, "
                        "1e-6, true, direct, [1, 2]); repeatable; checked like the file itself")


def parse_sets(sets: Sequence[str]) -> dict:
    """``["mesh.h=0.02", ...]`` -> the overrides of :func:`femkit.case.load_case` /
    :func:`femkit.study.load.load_study` (``{"mesh__h": 0.02}``); a malformed item is an
    :class:`~femkit.errors.InputError` naming it.

    >>> parse_sets(["mesh.h=0.02", "solver.rtol=1e-6", "output.png=true", "name=a=b"])
    {'mesh__h': 0.02, 'solver__rtol': 1e-06, 'output__png': True, 'name': 'a=b'}
    """
    from .errors import InputError

    out: dict = {}
    for item in sets:
        key, eq, text = item.partition("=")
        parts = key.strip().split(".")
        if not eq or not all(p.strip() for p in parts):
            raise InputError(f"--set {item!r}: expected KEY=VALUE with a dotted KEY, "
                             "e.g. --set mesh.h=0.02")
        import yaml

        from .case.load import _loader  # the case files' own reading (1e-6 is a number)

        try:
            value = yaml.load(text, Loader=_loader()) if text.strip() else ""
        except yaml.YAMLError as exc:
            problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
            raise InputError(f"--set {item!r}: the value is not valid YAML: {problem}") from None
        out["__".join(p.strip() for p in parts)] = value
    return out


def _add_solve(sub) -> None:
    p = _case_parser(
        sub, "solve", help="run a case file and write its results",
        description=(
            "Load CASE (YAML), validate it completely (schema, names, expressions, mesh file), "
            "build and check the mesh, assemble, solve, and write result.json plus the "
            "requested outputs (solution.vtu, solution.xdmf, solution.png) into the output "
            "directory, which appears only when the run finishes (atomically). Prints a short "
            "summary: mesh size, dofs, solver and iterations, true residual, error norms "
            "when the case gives an exact solution, and the time of each stage."),
        case_help="case file (.yaml), e.g. cases/poisson_lshape.yaml",
        quiet_help="print nothing on success", handler=_run_solve)
    p.add_argument("-o", "--output", metavar="DIR",
                   help="output directory (default: output.dir of the case, resolved against "
                        "the case file's directory)")
    p.add_argument("--backend", metavar="NAME",
                   help="linear-solver backend, replacing solver.backend of the case: femkit "
                        "(default) or petsc (PETSc + MPI: run as 'mpirun -n N femkit solve CASE "
                        "--backend petsc'; set up with scripts/install-petsc.sh)")
    _add_cost_flags(p)


def _add_cost_flags(p: argparse.ArgumentParser) -> None:
    """``--dry-run``, ``--max-memory``, ``--force`` (shared by ``solve`` and ``study``)."""
    p.add_argument("--dry-run", action="store_true",
                   help="print the predicted cost (sizes, time, peak memory, output per stage, "
                        "with the assumptions) and exit without running")
    p.add_argument("--max-memory", metavar="SIZE",
                   help="memory budget, e.g. 4GiB or 500MB (default: the available memory; "
                        "a case file's limits: {memory: ...} also applies)")
    p.add_argument("--force", action="store_true",
                   help="run even when the predicted cost exceeds a budget (warnings on stderr)")


def _max_memory(args) -> float | None:
    if getattr(args, "max_memory", None) is None:
        return None
    from .cost import parse_bytes

    return parse_bytes(args.max_memory, "--max-memory")


def _run_solve(args) -> int:
    from .case import load_case
    from .case.budget import check_case, plan_case
    from .interrupt import exit_code, stop_on_signals

    overrides = dict(args.overrides)
    if args.backend:
        overrides["solver__backend"] = args.backend
    case = load_case(args.case, **overrides)
    if args.dry_run:  # the plan, then what the run would say of it: a refusal exits 2 as it would
        from .case.budget import check_dry_run

        plan = plan_case(case)
        print(plan.render())
        sys.stdout.flush()
        for w in check_dry_run(case, plan, max_memory=_max_memory(args), force=args.force):
            print(f"femkit: warning: {w}", file=sys.stderr)
        return EXIT_OK
    check_case(case, max_memory=_max_memory(args), force=args.force)
    with stop_on_signals() as stop:
        case.run_options["stop"] = stop
        result = case.run(output_dir=args.output, quiet=args.quiet)
    if getattr(result, "interrupted", None):
        print(f"femkit: interrupted by {result.interrupted}; what was computed is written to "
              f"{getattr(result, 'output_dir', None)} (marked interrupted: true)", file=sys.stderr)
        return exit_code(stop)
    converged = bool(getattr(result, "converged", True))
    if not converged:
        where = getattr(result, "output_dir", None)
        # a run that failed for a reason of its own (e.g. an unstable integration) has already
        # printed that reason; only a plain non-convergence is named here
        what = "run failed" if getattr(result, "failure", None) else "solver did not converge"
        if _mpi_rank() == 0:
            print(f"femkit: {what}; results written to {where} (marked converged: false)",
                  file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


# ----------------------------------------------------------------------------- check

def _add_check(sub) -> None:
    _case_parser(
        sub, "check", help="cross-check a Poisson case against scikit-fem and pyamg",
        description=(
            "Build the case's mesh and compare, on that same mesh: femkit's stiffness matrix "
            "and one-point (barycentric) load vector with scikit-fem's (its Basis given the same centroid rule), "
            "femkit's solution with scikit-fem's (condense + direct solve), and the reduced "
            "system solved with pyamg's own smoothed-aggregation solver (accel='cg'). "
            "Prints each relative difference next to its tolerance; nothing is written. "
            "Tolerances: K and F 1e-12 relative; solutions 10*rtol relative (at least 1e-10)."),
        case_help="Poisson case file (.yaml)", quiet_help="print only failures",
        handler=_run_check, epilog=_CHECK_EPILOG)


def _run_check(args) -> int:
    from .case import load_case
    from .case.poisson.cross_check import cross_check, format_table

    case = load_case(args.case, **args.overrides)
    rows = cross_check(case)
    ok = all(r.passed for r in rows)
    if not args.quiet or not ok:
        print(format_table(rows))
    return EXIT_OK if ok else EXIT_FAILED


# ----------------------------------------------------------------------------- warmup

def _add_warmup(sub) -> None:
    p = sub.add_parser(
        "warmup", help="compile femkit's kernels now (once after an install; cached afterwards)",
        description=("Compile the compiled (numba) kernels of the Poisson pipeline (assembly, "
                     "edges, geometric multigrid) on a tiny problem, and generate and compile "
                     "the elastic solids' built-in material kernels, so the first real "
                     "'femkit solve' does not pay for it. Without it that first large run "
                     "compiles them itself, in a stage named 'compile'. Also writes the "
                     "bytecode (.pyc) of femkit's own modules, which Python does not write "
                     "itself under PYTHONDONTWRITEBYTECODE or a read-only install, so each "
                     "command does not compile them from source again."))
    p.set_defaults(handler=_run_warmup)


def _run_warmup(args) -> int:
    from .case.poisson.warmup import warm_up
    from .solids.warmup import warm_up as warm_up_solids

    print(f"kernels ready in {warm_up(print) + warm_up_solids():.1f} s")
    written, failed = byte_compile()
    print(f"bytecode of femkit's {written} modules written"
          + (f" ({failed} could not be written: a read-only install)" if failed else ""))
    return EXIT_OK


def byte_compile(root: str | None = None) -> tuple[int, int]:
    """Write the bytecode (``__pycache__/*.pyc``) of every module under ``root`` (default: the
    installed femkit package); ``(modules written or up to date, modules that failed)``.

    Python reads a ``.pyc`` whenever it is up to date with its source, but writes none under
    ``PYTHONDONTWRITEBYTECODE=1`` or where it cannot write: each process then compiles every
    femkit module it imports from source again (about 0.2 s of a ``femkit solve``).
    :mod:`py_compile` writes regardless of that variable. A source edited later makes its
    ``.pyc`` stale (its recorded modification time differs), and Python ignores it.
    """
    import os
    import py_compile
    from importlib.util import cache_from_source

    base = root if root is not None else os.path.dirname(os.path.abspath(__file__))
    written = failed = 0
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__" and not d.startswith("."))
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            source = os.path.join(folder, name)
            try:
                py_compile.compile(source, cfile=cache_from_source(source), doraise=True)
                written += 1
            except (py_compile.PyCompileError, OSError):
                failed += 1
    return written, failed


def _add_study(sub) -> None:
    from .study.cli import add_parser  # standard library only at import time

    p = add_parser(sub)
    _add_set_flag(p)
    p.epilog_fn = _study_epilog
    p.formatter_class = argparse.RawDescriptionHelpFormatter


# ----------------------------------------------------------------------------- list

#: the groups of ``femkit list`` (kept equal to femkit.catalog.GROUPS by a test; listed here so
#: that ``femkit list --help`` imports nothing)
LIST_GROUPS = ("geometries", "solvers", "preconditioners", "backends", "integrators", "forces",
               "systems", "materials", "problems", "studies")


def _add_list(sub) -> None:
    p = sub.add_parser(
        "list", help="list the names case and study files may use (geometries, solvers, ...)",
        description=(
            "Print every registered name of each GROUP with one line on what it is: "
            + ", ".join(LIST_GROUPS) + " (default: all). Read from the live registries, "
            "plugins included, so it is never out of date. Nothing is written."),
        epilog="exit codes:\n  0  listed\n  2  unknown group (the valid ones are named)\n\n"
               "examples:\n  femkit list\n  femkit list solvers preconditioners\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("groups", nargs="*", metavar="GROUP", help="a group (singular accepted: solver)")
    p.set_defaults(handler=_run_list)


def _list_group(name: str) -> str:
    """``solver`` -> ``solvers``, ``geometry`` -> ``geometries``, ``study`` -> ``studies``."""
    for group in LIST_GROUPS:
        if name in (group, group[:-1], group[:-3] + "y"):
            return group
    return name  # unknown: femkit.catalog names the valid groups


def _run_list(args) -> int:
    from .catalog import render

    print(render([_list_group(g) for g in args.groups]))
    return EXIT_OK


#: Subcommands, in help order: each adds its parser to the subparsers object.
SUBCOMMANDS: list[Callable] = [_add_solve, _add_check, _add_study, _add_list, _add_warmup]


def build_parser() -> argparse.ArgumentParser:
    """The ``femkit`` argument parser (no heavy import happens here)."""
    parser = _Parser(
        prog="femkit",
        description=("femkit: P1 finite elements for Poisson problems (and mass-spring "
                     "dynamics), every result reported with its error and its cost."),
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    from ._version import __version__

    parser.add_argument("--version", action="version", version=f"femkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for add in SUBCOMMANDS:
        add(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``femkit`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    from .errors import FemkitError, InputError
    from .interrupt import Interrupted

    handler = getattr(args, "handler", None) or getattr(args, "func")  # func: femkit.study.cli style
    from .allocator import from_environment

    from_environment()  # FEMKIT_RETURN_MEMORY=1: freed arrays go back to the system at once
    speaks = _mpi_rank() == 0  # under mpirun every rank raises the same error: rank 0 says it
    try:
        args.overrides = parse_sets(getattr(args, "sets", ()))
        return int(handler(args))
    except InputError as exc:
        if speaks:
            print(f"femkit: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except FemkitError as exc:
        if speaks:
            print(f"femkit: failed: {_one_line(exc)}", file=sys.stderr)
        return EXIT_FAILED
    except Interrupted as exc:  # stopped between stages: nothing was written
        print(f"femkit: {exc}; nothing written", file=sys.stderr)
        return 128 + int(exc.flag.signum or 2)
    except KeyboardInterrupt:
        print("femkit: interrupted", file=sys.stderr)
        return 130


def _mpi_rank() -> int:
    """This process's MPI rank from the launcher's environment (0 outside mpirun)."""
    import os

    for var in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"):
        if os.environ.get(var, "").isdigit():
            return int(os.environ[var])
    return 0


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def entry() -> None:
    """The ``femkit`` console script and ``python -m femkit``: :func:`main`, then the exit.

    The process ends with :func:`_exit_now` rather than the interpreter's own teardown, which
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
    _defer_unused_imports()
    code = main()
    from .interrupt import abandoned_work

    stopped = code in (130, 143) or abandoned_work()
    if not stopped and (sys.getprofile() is not None or sys.gettrace() is not None):
        sys.exit(code)  # under a profiler or a debugger, which write their results after us
    if not stopped and any(m in sys.modules for m in _FINALIZE_AT_EXIT):
        sys.exit(code)  # MPI / PETSc finalise in the interpreter's own exit (mpirun needs it)
    _exit_now(code, clean=not stopped)


#: modules whose libraries must be finalised by the interpreter's own exit (C-level exit
#: handlers that ``os._exit`` skips): mpi4py's ``MPI_Finalize`` (without it ``mpirun`` reports
#: the rank as exiting improperly and fails the run) and PETSc's ``PetscFinalize``.
_FINALIZE_AT_EXIT = ("mpi4py", "petsc4py")


#: numpy's submodules that no femkit command uses but every process imported: scipy's array-API
#: layer (``scipy._lib.array_api_compat.numpy``, imported by ``scipy.sparse``, ``scipy.linalg``
#: and numba's BLAS check) reads every name of ``numpy.__all__``, and numpy imports a submodule
#: when its name is read: ``numpy.f2py`` (the Fortran wrapper generator, ~0.15 s) and
#: ``numpy.testing`` (``unittest`` with it). (``numpy.ma`` is in use: ``np.unique`` asks it.)
DEFERRED_IMPORTS = ("numpy.f2py", "numpy.testing")


class _Deferred:
    """A :data:`sys.meta_path` finder giving the modules of :data:`DEFERRED_IMPORTS` Python's
    :class:`importlib.util.LazyLoader`: importing one makes its module object, executed when
    an attribute of it is first used. Only the command's own process installs it (:func:`entry`)."""

    def __init__(self, names) -> None:
        self.names = set(names)

    def find_spec(self, name, path=None, target=None):
        if name not in self.names:
            return None
        self.names.discard(name)  # once: the module is in sys.modules from now on
        import importlib.machinery
        import importlib.util

        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        spec.loader = importlib.util.LazyLoader(spec.loader)
        return spec


def _defer_unused_imports() -> None:
    """Install :class:`_Deferred` (nothing is imported now) unless a module is imported already."""
    if not any(name in sys.modules for name in DEFERRED_IMPORTS):
        sys.meta_path.insert(0, _Deferred(DEFERRED_IMPORTS))


def _exit_now(code: int, *, clean: bool = True) -> None:
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


if __name__ == "__main__":  # pragma: no cover
    entry()
