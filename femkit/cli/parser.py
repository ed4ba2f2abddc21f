"""The ``femkit`` command line's parser: every subcommand's flags, help and epilog, and
``--set``; :func:`build_parser` builds it, each subcommand's ``handler`` does the work.

This module imports only the standard library at module level, so ``femkit --help`` is
instant; each subcommand imports what it needs when it runs.

Exit codes: :mod:`femkit.cli`.

Adding a subcommand: write ``_add_<name>(sub)`` that declares its parser and sets
``handler`` (or ``func``; a function ``args -> int``, e.g. in :mod:`femkit.cli.commands`), then
append it to :data:`SUBCOMMANDS`.
"""

from __future__ import annotations

import argparse
import sys
from typing import Callable, Sequence

from .commands import run_check, run_solve, run_view, run_warmup
from .messages import EXIT_BAD_INPUT, EXIT_OK

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
    from ..catalog import entries

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
    from ..errors import InputError

    out: dict = {}
    for item in sets:
        key, eq, text = item.partition("=")
        parts = key.strip().split(".")
        if not eq or not all(p.strip() for p in parts):
            raise InputError(f"--set {item!r}: expected KEY=VALUE with a dotted KEY, "
                             "e.g. --set mesh.h=0.02")
        import yaml

        from ..case.load import _loader  # the case files' own reading (1e-6 is a number)

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
        quiet_help="print nothing on success", handler=run_solve)
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



# ----------------------------------------------------------------------------- check

def _add_check(sub) -> None:
    _case_parser(
        sub, "check", help="cross-check a Poisson case against scikit-fem and pyamg",
        description=(
            "Build the case's mesh and compare, on that same mesh: femkit's stiffness matrix "
            "and load vector with scikit-fem's (the case's quadrature.load rule on both sides: "
            "scikit-fem's Basis is given its points and weights), "
            "femkit's solution with scikit-fem's (condense + direct solve), and the reduced "
            "system solved with pyamg's own smoothed-aggregation solver (accel='cg'). "
            "Prints each relative difference next to its tolerance; nothing is written. "
            "Tolerances: K and F 1e-12 relative; solutions 10*rtol relative (at least 1e-10)."),
        case_help="Poisson case file (.yaml)", quiet_help="print only failures",
        handler=run_check, epilog=_CHECK_EPILOG)




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
    p.set_defaults(handler=run_warmup)




def _add_study(sub) -> None:
    from ..study.cli import add_parser  # standard library only at import time

    p = add_parser(sub)
    _add_set_flag(p)
    p.epilog_fn = _study_epilog
    p.formatter_class = argparse.RawDescriptionHelpFormatter


# ----------------------------------------------------------------------------- list

def _add_list(sub) -> None:
    from ..catalog import GROUPS  # the groups themselves; importing it loads no registry

    p = sub.add_parser(
        "list", help="list the names case and study files may use (geometries, solvers, ...)",
        description=(
            "Print every registered name of each GROUP with one line on what it is: "
            + ", ".join(GROUPS) + " (default: all). Read from the live registries, "
            "plugins included, so it is never out of date. Nothing is written."),
        epilog="exit codes:\n  0  listed\n  2  unknown group (the valid ones are named)\n\n"
               "examples:\n  femkit list\n  femkit list solvers preconditioners\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("groups", nargs="*", metavar="GROUP", help="a group (singular accepted: solver)")
    p.set_defaults(handler=_run_list)


def _list_group(name: str) -> str:
    """``solver`` -> ``solvers``, ``geometry`` -> ``geometries``, ``study`` -> ``studies``."""
    from ..catalog import GROUPS

    for group in GROUPS:
        if name in (group, group[:-1], group[:-3] + "y"):
            return group
    return name  # unknown: femkit.catalog names the valid groups


def _run_list(args) -> int:
    from ..catalog import render

    print(render([_list_group(g) for g in args.groups]))
    return EXIT_OK


# ----------------------------------------------------------------------------- view

_VIEW_EPILOG = """\
exit codes:
  0  shown, or the files written
  2  bad input (neither a run nor a study directory, an unknown --field: the valid
     ones are named, an unknown file type), or no pyvista (pip install
     femkit[view]), or neither a display nor off-screen OpenGL (EGL/OSMesa:
     scripts/install-view.sh); one line, nothing written

examples:
  femkit view runs/fichera
  femkit view runs/fichera --screenshot fichera.png
  femkit view runs/hanging_cloth --field stretch --movie cloth.gif
  femkit view femkit-out/poisson_convergence --field work_precision --screenshot wp.png
"""


def _add_view(sub) -> None:
    p = sub.add_parser(
        "view", help="look at a run's results (pyvista: pip install femkit[view])",
        description=(
            "Draw the results of the run in RUN_DIR (the output directory of 'femkit solve') as "
            "its kind draws them: a Poisson solution (3D: clipped open), a solid warped by its "
            "displacement and coloured by its stress over its rest shape, a scene with its "
            "obstacles; a time series frame by frame. A study's output directory (of 'femkit "
            "study') is drawn as its report's first figure (--field: another, by name). In a window with a frame slider where a "
            "display exists; --screenshot and --movie render off screen (also where there is no "
            "display); with neither and no display, RUN_DIR's picture is written to "
            "<case>-<field>.png here. Files are written atomically."),
        epilog=_VIEW_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run_dir", metavar="RUN_DIR",
                   help="a run directory (holding result.json) or a study's output directory "
                   "(report.md, results.json)")
    p.add_argument("--field", metavar="NAME",
                   help="the field to colour by (default: the kind's; an unknown one lists them)")
    p.add_argument("--screenshot", metavar="FILE", help="write the last frame to FILE (.png)")
    p.add_argument("--movie", metavar="FILE",
                   help="write every frame to FILE (.gif; .mp4 with imageio-ffmpeg)")
    p.add_argument("--size", metavar="WxH", default="1280x960",
                   help="picture size in pixels (default 1280x960)")
    p.set_defaults(handler=run_view)


#: Subcommands, in help order: each adds its parser to the subparsers object.
SUBCOMMANDS: list[Callable] = [_add_solve, _add_check, _add_study, _add_list, _add_warmup,
                               _add_view]


def build_parser() -> argparse.ArgumentParser:
    """The ``femkit`` argument parser (no heavy import happens here)."""
    parser = _Parser(
        prog="femkit",
        description=("femkit: P1 finite elements for Poisson problems (and mass-spring "
                     "dynamics), every result reported with its error and its cost."),
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    from .._version import __version__

    parser.add_argument("--version", action="version", version=f"femkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for add in SUBCOMMANDS:
        add(sub)
    return parser
