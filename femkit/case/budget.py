"""The budget check of a case or scene file before it runs (``femkit solve``, ``--dry-run``).

:func:`plan_case` translates a loaded case into a :class:`femkit.cost.Plan` through its
kind (``KINDS[...].plan``); :func:`check_case` checks it against the case's
``limits:``, the command line's ``--max-memory`` and the available memory, refusing with
:class:`~femkit.errors.BudgetExceededError` (exit code 2, one line) unless forced.

Run options travel in ``case.options`` (:class:`femkit.case.load.RunOptions`, typed and
frozen; a new case carries changed ones: ``case.with_options(...)``): ``limits``
(:class:`femkit.cost.Limits`, from the file), ``force`` (skip every budget, also the memory guard before meshing:
:func:`femkit.case.cost.check_mesh_fits`), ``stop`` (a :class:`femkit.interrupt.StopFlag` the
runners check between steps and iterations) and ``plan`` (in the case :func:`check_case` returns: a Poisson
run predicted to last 30 s or more prints a line on stderr after each stage with the elapsed
and the predicted remaining time).
"""

from __future__ import annotations

import dataclasses
import sys

from ..cost import Limits, Plan, check_budget, with_default_time
from .cost import OVERRIDE

__all__ = ["plan_case", "check_case", "check_dry_run"]

#: Without a stated time limit, a run is measured (and checked against the default budget,
#: :data:`femkit.cost.budget.DEFAULT_TIME_BUDGET`) only when the model predicts more than this
#: fraction of it.
MEASURE_FRACTION = 0.1

#: How a user goes past the default time budget (quoted in the refusal).
RAISE_TIME = f"{OVERRIDE} or a larger limits: {{time: ...}}"


def plan_case(case, *, measure: bool = True) -> Plan:
    """The plan of any case, through its kind (``KINDS[case.problem].plan``)."""
    from ..kinds import KINDS

    kind = KINDS.get(case.problem, "problem")
    if kind.plan is None:  # a kind without a cost model runs unchecked, and the plan says so
        from ..cost import load_constants

        return Plan("case", f"{case.name}: {case.problem}", {}, [],
                    load_constants()["bytes"]["baseline"],
                    assumptions=[f"no cost model for problem {case.problem!r}: the run is unchecked"])
    return kind.plan(case, measure=measure)


def _limits(case, max_memory: float | None) -> tuple[Limits, Limits, Limits]:
    """The case's limits (the file's, ``max_memory``, the default time budget), and them split
    into the untimed part (memory, steps, output) and the time limit."""
    limits = with_default_time(case.options.limits)
    if max_memory is not None:
        limits = limits.merged(Limits(memory=max_memory))
    untimed = dataclasses.replace(limits, time=None, time_is_default=False)
    timed = Limits(time=limits.time, check_available=False, time_is_default=limits.time_is_default)
    return limits, untimed, timed


def check_case(case, *, max_memory: float | None = None, force: bool = False,
               echo=None):
    """Plan ``case`` and refuse it when it exceeds a budget (before anything runs).

    Limits: the file's ``limits:``, ``max_memory`` (bytes, ``--max-memory``), the available
    memory and, when the file states no time limit, the default time budget
    (:data:`femkit.cost.budget.DEFAULT_TIME_BUDGET`, one hour). Steps and memory are checked on
    the model alone (immediately, however large the run); a time limit first measures: the
    machine's speed (Poisson) or a batch of steps (scenes), for the default budget only when the
    model predicts more than :data:`MEASURE_FRACTION` of it. With ``force`` the violations are printed as warnings on stderr and the run goes on (also past the
    memory guard before meshing: ``options.force``).

    Returns
    -------
    Case
        ``case`` with ``options.force`` and ``options.plan`` (the plan checked) set: the case
        to run.

    Raises
    ------
    BudgetExceededError
        A limit is exceeded and ``force`` is false.
    """
    limits, untimed, timed = _limits(case, max_memory)
    case = case.with_options(force=bool(force))
    say = echo or (lambda line: print(line, file=sys.stderr))
    plan = plan_case(case, measure=False)
    warnings = check_budget(plan, untimed, force=force, override=OVERRIDE)
    # a stated time limit is checked on a measured plan; the default budget only when the model
    # puts the run near it (a tenth of it), so short runs pay no measurement
    if not limits.time_is_default or plan.seconds > MEASURE_FRACTION * limits.time:
        plan = plan_case(case, measure=True)
        warnings += check_budget(plan, timed, force=force, override=RAISE_TIME
                                 if limits.time_is_default else OVERRIDE)
    for w in warnings:
        w = w.replace(f" (or {OVERRIDE} to run anyway)", "").replace(f" (or {RAISE_TIME} to run anyway)", "")
        say(f"femkit: warning: {w} ({OVERRIDE} given)")
    return case.with_options(plan=plan)  # long Poisson runs report each stage against it


def check_dry_run(case, plan: Plan, *, max_memory: float | None = None,
                  force: bool = False) -> list[str]:
    """What ``femkit solve --dry-run`` adds to the printed ``plan``: the refusal the run would
    meet (the same limits as :func:`check_case`: the file's, ``max_memory``, the available memory,
    the default time budget), raised as it would be; with ``force`` the warnings the run would
    print instead.

    Raises
    ------
    BudgetExceededError
        The run would be refused (its one line), unless ``force``.
    """
    limits, untimed, timed = _limits(case, max_memory)
    warnings = check_budget(plan, untimed, force=force, override=OVERRIDE)
    warnings += check_budget(plan, timed, force=force,
                             override=RAISE_TIME if limits.time_is_default else OVERRIDE)
    return warnings
