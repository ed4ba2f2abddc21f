"""``femkit study STUDY.yaml``: argparse pieces for femkit/cli.py.

``add_parser(subparsers)`` adds the ``study`` subcommand; ``cli_main(args) -> int`` runs it
(``args`` an argparse namespace from that parser, or a list of strings). Exit codes: 0 ok,
2 bad input (one-line message on stderr), 1 when some run failed to converge or went unstable
where the study did not expect it is *not* an error: a study reports failures as data.

BLAS threads are pinned (``OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=MKL_NUM_THREADS=1`` unless
already set) by :func:`cli_main`, before the study imports numpy, so timings are comparable.
Importing this module has no side effect (``femkit solve`` builds the same parser).
"""

from __future__ import annotations

import argparse
import sys

from .timing import pin_blas_threads

HELP = "run a study file (convergence, work-precision or stability sweep) and write its report"


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add the ``study`` subcommand to an argparse ``subparsers`` object; returns its parser."""
    p = subparsers.add_parser(
        "study", help=HELP, description=HELP + ". Writes report.md, report.html (figures embedded), "
        "figures/*.png, runs.csv and results.json into the output directory, replaced atomically.")
    _arguments(p)
    p.set_defaults(func=cli_main)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("study", help="study YAML file (kind: poisson_convergence | dynamics_work_precision | stability)")
    p.add_argument("-o", "--output", help="report directory (default: the file's output: key, "
                   "else femkit-out/<name> beside the study file)")
    p.add_argument("--quick", action="store_true", help="apply the file's quick: block (small sizes)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def cli_main(args) -> int:
    """Run ``femkit study``; ``args`` is a namespace from :func:`add_parser` or a list of strings."""
    if not isinstance(args, argparse.Namespace):
        p = argparse.ArgumentParser(prog="femkit study", description=HELP)
        _arguments(p)
        args = p.parse_args(list(args))
    pin_blas_threads(1)
    from ..errors import InputError
    from .load import load_study
    from .run import run_study

    try:
        study = load_study(args.study, quick=args.quick)
        result = run_study(study, args.output, progress=False if args.no_progress else None)
    except InputError as exc:
        print(f"femkit study: error: {exc}", file=sys.stderr)
        return 2
    print(f"{study.kind} '{study.name}': {len(result.records)} runs in {result.elapsed:.1f} s")
    from .kinds import STUDY_KINDS

    for line in STUDY_KINDS.get(study.kind).summary(result):
        print(f"  {line}")
    for line in result.notes:
        print(f"  note: {line}")
    print(f"report: {result.output_dir / 'report.html'}")
    return 0
