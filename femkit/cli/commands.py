"""What each ``femkit`` subcommand does once its arguments are parsed: ``handler(args) -> exit
code`` (the parsers in :mod:`femkit.cli.parser` name them). Each imports what it needs when it
runs, so that ``femkit --help`` imports none of it.
"""

from __future__ import annotations

import sys

from .messages import EXIT_FAILED, EXIT_OK, mpi_rank


def max_memory(args) -> float | None:
    """``--max-memory`` in bytes (``None`` when not given)."""
    if getattr(args, "max_memory", None) is None:
        return None
    from ..cost import parse_bytes

    return parse_bytes(args.max_memory, "--max-memory")


def run_solve(args) -> int:
    """``femkit solve``: load the case, plan it (``--dry-run``) or check its budget, run it."""
    from ..case import load_case
    from ..case.budget import check_case, plan_case
    from ..interrupt import exit_code, stop_on_signals

    overrides = dict(args.overrides)
    if args.backend:
        overrides["solver__backend"] = args.backend
    case = load_case(args.case, **overrides)
    if args.dry_run:  # the plan, then what the run would say of it: a refusal exits 2 as it would
        from ..case.budget import check_dry_run

        plan = plan_case(case)
        print(plan.render())
        sys.stdout.flush()
        for w in check_dry_run(case, plan, max_memory=max_memory(args), force=args.force):
            print(f"femkit: warning: {w}", file=sys.stderr)
        return EXIT_OK
    case = check_case(case, max_memory=max_memory(args), force=args.force)
    with stop_on_signals() as stop:
        result = case.with_options(stop=stop).run(output_dir=args.output, quiet=args.quiet)
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
        if mpi_rank() == 0:
            print(f"femkit: {what}; results written to {where} (marked converged: false)",
                  file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def run_check(args) -> int:
    """``femkit check``: cross-check a Poisson case against scikit-fem and pyamg."""
    from ..case import load_case
    from ..case.poisson.cross_check import cross_check, format_table

    case = load_case(args.case, **args.overrides)
    rows = cross_check(case)
    ok = all(r.passed for r in rows)
    if not args.quiet or not ok:
        print(format_table(rows))
    return EXIT_OK if ok else EXIT_FAILED


def run_warmup(args) -> int:
    """``femkit warmup``: compile the kernels and write femkit's bytecode."""
    from ..case.poisson.warmup import warm_up
    from ..solids.warmup import warm_up as warm_up_solids

    from .bytecode import byte_compile

    print(f"kernels ready in {warm_up(print) + warm_up_solids():.1f} s")
    written, failed = byte_compile()
    print(f"bytecode of femkit's {written} modules written"
          + (f" ({failed} could not be written: a read-only install)" if failed else ""))
    return EXIT_OK


def _size(text: str) -> tuple[int, int]:
    """``"1280x960"`` -> ``(1280, 960)``; anything else an InputError naming the form."""
    from ..errors import InputError

    w, x, h = text.lower().partition("x")
    if not (x and w.isdigit() and h.isdigit() and 16 <= int(w) <= 8192 and 16 <= int(h) <= 8192):
        raise InputError(f"--size {text!r}: expected WIDTHxHEIGHT in pixels, e.g. 1280x960")
    return int(w), int(h)


def run_view(args) -> int:
    """``femkit view``: draw a run directory (window, ``--screenshot``, ``--movie``)."""
    from pathlib import Path

    from ..view import open_view
    from ..view.core.render import check_movie_path, display_available

    size = _size(args.size)
    if args.movie:  # a bad file type is refused before anything is drawn
        check_movie_path(Path(args.movie))
    if args.screenshot and Path(args.screenshot).suffix.lower() != ".png":
        from ..errors import InputError

        raise InputError(f"--screenshot {args.screenshot}: a screenshot is a .png file")
    view = open_view(args.run_dir, field=args.field, size=size)
    written = []
    if args.screenshot:
        written.append(view.screenshot(args.screenshot))
    if args.movie:
        written.append(view.movie(args.movie))
    if not written and display_available():
        view.show()
    elif not written:
        name = f"{view.picture.title.split(':')[0]}-{view.picture.field}.png"
        written.append(view.screenshot(name))
    for path in written:
        print(f"wrote {path}")
    return EXIT_OK
