"""The cost of a ``solid_load`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``solid_load`` study: each material's run priced by the solid kind's plan
    (:func:`femkit.case.solid.cost.plan_solid_case`) of the case it runs."""
    from ...kinds import KINDS
    from .run import material_cases

    stages, assumptions = [], []
    for name, case in material_cases(study):
        plan = KINDS.get("solid", "problem").plan(case, measure=False)
        stages.append(Stage(name, plan.seconds, plan.peak_bytes - plan.baseline_bytes,
                            detail=f"{study.spec.load_steps} load steps"))
        assumptions = plan.assumptions
    return runs_plan(study, stages, len(stages), assumptions[:3])
