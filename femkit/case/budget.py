"""The budget check of a case or scene file before it runs (``femkit solve``, ``--dry-run``).

:func:`plan_case` translates a loaded case into a :class:`femkit.cost.Plan` through its
kind (``KINDS[...].plan``); :func:`check_case` checks it against the case's
``limits:``, the command line's ``--max-memory`` and the available memory, refusing with
:class:`~femkit.errors.BudgetExceededError` (exit code 2, one line) unless forced.

Run options travel in ``case.run_options``: ``limits`` (:class:`femkit.cost.Limits`, from the
file), ``force`` (skip every budget, also the memory guard before meshing:
:func:`femkit.case.cost.check_mesh_fits`), ``stop`` (a :class:`femkit.interrupt.StopFlag` the
runners check between steps and iterations) and ``plan`` (set by :func:`check_case`: a Poisson
run predicted to last 30 s or more prints a line on stderr after each stage with the elapsed
and the predicted remaining time).
"""

from __future__ import annotations

import sys

from ..cost import Limits, Plan, check_budget
from .cost import OVERRIDE

__all__ = ["plan_case", "check_case"]


def plan_case(case, *, measure: bool = True) -> Plan:
    """The plan of any case, through its kind (``KINDS[case.problem].plan``)."""
    from .kinds import KINDS

    kind = KINDS.get(case.problem, "problem")
    if kind.plan is None:  # a kind without a cost model runs unchecked, and the plan says so
        from ..cost import load_constants

        return Plan("case", f"{case.name}: {case.problem}", {}, [],
                    load_constants()["bytes"]["baseline"],
                    assumptions=[f"no cost model for problem {case.problem!r}: the run is unchecked"])
    return kind.plan(case, measure=measure)


def check_case(case, *, max_memory: float | None = None, force: bool = False,
               echo=None) -> Plan:
    """Plan ``case`` and refuse it when it exceeds a budget (before anything runs).

    Limits: the file's ``limits:``, ``max_memory`` (bytes, ``--max-memory``) and the available
    memory. Steps and memory are checked on the model alone (immediately, however large the
    run); a time limit first measures: the machine's speed (Poisson) or a batch of steps (scenes). With ``force`` the
    violations are printed as warnings on stderr and the run goes on (also past the
    memory guard before meshing: ``case.run_options["force"]``).

    Raises
    ------
    BudgetExceededError
        A limit is exceeded and ``force`` is false.
    """
    limits = case.run_options.get("limits") or Limits()
    if max_memory is not None:
        limits = limits.merged(Limits(memory=max_memory))
    case.run_options["force"] = bool(force)
    say = echo or (lambda line: print(line, file=sys.stderr))
    untimed = Limits(limits.memory, None, limits.steps, limits.output, limits.check_available)
    plan = plan_case(case, measure=False)
    warnings = check_budget(plan, untimed, force=force, override=OVERRIDE)
    if limits.time is not None:
        plan = plan_case(case, measure=True)
        warnings += check_budget(plan, Limits(time=limits.time, check_available=False),
                                 force=force, override=OVERRIDE)
    for w in warnings:
        say(f"femkit: warning: {w.replace(f' (or {OVERRIDE} to run anyway)', '')} ({OVERRIDE} given)")
    case.run_options["plan"] = plan  # long Poisson runs report each stage against it
    return plan
