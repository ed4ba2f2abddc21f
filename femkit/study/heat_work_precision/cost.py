"""The cost of a ``heat_work_precision`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan

__all__ = ["plan"]


def plan(study) -> Plan:
    """Each run priced by the heat kind's plan of the case it runs
    (:func:`femkit.case.heat.cost.plan_heat_case`), one stage per mesh size, times the repeats."""
    from ...kinds import KINDS
    from ..spec import load_base_case as base_case

    d = study.spec
    stages, assumptions = [], []
    for h in d.h:
        seconds, peak = 0.0, 0.0
        for name in d.schemes:
            for dt in d.dt:
                _, case = base_case(study, mesh={"h": h}, integrator=name, dt=dt,
                                    output={"frames": 1})
                p = KINDS.get("heat", "problem").plan(case, measure=False)
                seconds += p.seconds * max(1, d.repeats)
                peak = max(peak, p.peak_bytes - p.baseline_bytes)
                assumptions = p.assumptions
        stages.append(Stage(f"h={h:g}", seconds, peak,
                            detail=f"{len(d.schemes) * len(d.dt)} runs"))
    return runs_plan(study, stages, len(d.h) * len(d.schemes) * len(d.dt), assumptions[:3])
