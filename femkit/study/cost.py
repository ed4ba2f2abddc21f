"""The cost of a study before it runs (``femkit study STUDY --dry-run``, budgets).

Each study kind prices itself (``femkit/study/<kind>/cost.py``, its ``Kind.plan``): the plan sums
the runs its sweep will do, each priced by the cost model (:mod:`femkit.cost`) from numbers
(the shared per-run prices: :mod:`femkit.study.prices`); library imports are counted once (each
sweep's warm-up pays them). This module is the dispatch, :func:`plan_study`, and the shared
constructor :func:`runs_plan`; ``femkit study --dry-run`` prints the plan and the default time
budget (:data:`femkit.cost.DEFAULT_TIME_BUDGET`) is checked against it.
"""

from __future__ import annotations

from ..cost import Plan

__all__ = ["plan_study", "runs_plan"]


def plan_study(study, *, speed: float = 1.0) -> Plan:
    """The plan of any study, through its kind (``KINDS[study.kind].plan``), its seconds
    multiplied by ``speed`` (:func:`femkit.cost.machine_speed`: this machine against the one the
    constants were fitted on); a kind without a cost model gets a plan that says so."""
    from ..kinds import KINDS

    kind = KINDS.get(study.kind, "kind")
    if kind.plan is not None:
        plan = kind.plan(study)
        if speed != 1.0:
            for stage in plan.stages:
                stage.seconds *= speed
            plan.assumptions.append(f"seconds scaled by this machine's speed now (x{speed:.2f})")
        return plan
    from ..cost import load_constants

    return Plan("study", f"{study.name}: {study.kind}", {}, [],
                load_constants()["bytes"]["baseline"], assumptions=[f"no cost model for study kind {study.kind!r} yet: only its "
                             "mesh sizes and time steps bound the cost"])


def runs_plan(study, stages: list, runs: int, assumptions: list) -> Plan:
    """A study's plan from its priced stages (one per group of runs)."""
    from ..cost import load_constants

    return Plan("study", f"{study.name}: {study.kind}, {runs} runs", {"runs": runs}, stages,
                load_constants()["bytes"]["baseline"], assumptions)

