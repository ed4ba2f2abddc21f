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
    p.add_argument("study", help="study YAML file (its kind: one of the study kinds below)")
    p.add_argument("-o", "--output", help="report directory (default: the file's output: key, "
                   "else femkit-out/<name> beside the study file)")
    p.add_argument("--quick", action="store_true", help="apply the file's quick: block (small sizes)")
    p.add_argument("--no-progress", "-q", "--quiet", dest="no_progress", action="store_true",
                   help="no progress (a bar on a terminal, else one line per 10 %% of the runs "
                        "or per minute on stderr)")
    p.add_argument("--dry-run", action="store_true",
                   help="print the predicted cost of the sweep and exit without running it")
    p.add_argument("--max-memory", metavar="SIZE",
                   help="memory budget, e.g. 4GiB (default: the available memory)")
    p.add_argument("--force", action="store_true",
                   help="run even when the predicted cost exceeds a budget")


def _check_cost(study, args) -> bool:
    """``--dry-run``: print the plan (True: done); else refuse a sweep that cannot fit in the
    memory or is predicted to outlast the default time budget."""
    from ..case.budget import MEASURE_FRACTION
    from ..cost import Limits, check_budget, machine_speed, parse_bytes, with_default_time
    from .cost import plan_study

    max_memory = getattr(args, "max_memory", None)
    # the default time budget (one hour, femkit.cost.DEFAULT_TIME_BUDGET): --force runs past it;
    # the machine's speed is probed only for a sweep the model puts near it
    limits = with_default_time(Limits(
        memory=None if max_memory is None else parse_bytes(max_memory, "--max-memory")))
    dry = getattr(args, "dry_run", False)
    if dry:  # the plan, then what the run would say of it (a refusal exits 2 as it would)
        plan = plan_study(study, speed=machine_speed())
        print(plan.render())
        sys.stdout.flush()
    else:
        plan = plan_study(study)
    if not dry and plan.seconds > MEASURE_FRACTION * limits.time:
        plan = plan_study(study, speed=machine_speed())
    for w in check_budget(plan, limits, force=getattr(args, "force", False), override="--force"):
        print(f"femkit study: warning: {w} (--force given)", file=sys.stderr)
    return dry


def cli_main(args) -> int:
    """Run ``femkit study``; ``args`` is a namespace from :func:`add_parser` or a list of strings."""
    if not isinstance(args, argparse.Namespace):
        p = argparse.ArgumentParser(prog="femkit study", description=HELP)
        _arguments(p)
        args = p.parse_args(list(args))
    from .timing import pin_blas_threads  # here: `femkit solve` builds this parser too

    pin_blas_threads(1)
    from ..errors import InputError
    from .load import load_study
    from .run import run_study

    from ..interrupt import Interrupted, raising, stop_on_signals

    study = None
    with stop_on_signals():  # until the end: a signal after the sweep must not kill the summary
        try:
            with raising("loading the study file"):  # a signal stops the parse and checks at once
                study = load_study(args.study, quick=args.quick, **getattr(args, "overrides", {}))
            if _check_cost(study, args):
                return 0
            result = run_study(study, args.output, progress=False if args.no_progress else None)
        except InputError as exc:
            print(f"femkit study: error: {exc}", file=sys.stderr)
            return 2
        except Interrupted as exc:
            if study is None:
                print(f"femkit study: {exc}; nothing written", file=sys.stderr)
                return 128 + int(exc.flag.signum or 2)
            out = args.output if args.output is not None else study.default_output()
            print(f"femkit study: {exc}; nothing written, the earlier report in {out} (if any) is "
                  "kept as it was", file=sys.stderr)
            return 128 + int(exc.flag.signum or 2)
        print(f"{study.kind} '{study.name}': {len(result.records)} runs in {result.elapsed:.1f} s")
        from ..kinds import KINDS

        summary = KINDS.get(study.kind, "kind").summary
        for line in (summary(result) if summary else ()):
            print(f"  {line}")
        for line in result.notes:
            print(f"  note: {line}")
        print(f"report: {result.output_dir / 'report.html'}")
        return 0
