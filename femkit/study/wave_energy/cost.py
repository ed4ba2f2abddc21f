"""The cost of a ``wave_energy`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan

__all__ = ["plan"]


def plan(study) -> Plan:
    """Each run priced by the wave kind's plan of the case it runs
    (:func:`femkit.case.wave.cost.plan_wave_case`), one stage per integrator."""
    from ...kinds import KINDS
    from .run import FRAMES
    from ..spec import load_base_case as base_case

    d = study.spec
    _, base = base_case(study)
    stages, assumptions = [], []
    for name in d.schemes:
        seconds, peak = 0.0, 0.0
        for n in d.steps:
            _, case = base_case(study, integrator=name, dt=base.spec.t_end / n,
                                output={"frames": min(n, FRAMES)})
            p = KINDS.get("wave", "problem").plan(case, measure=False)
            seconds += p.seconds
            peak = max(peak, p.peak_bytes - p.baseline_bytes)
            assumptions = p.assumptions
        stages.append(Stage(name, seconds, peak, detail=f"{len(d.steps)} runs"))
    return runs_plan(study, stages, len(d.schemes) * len(d.steps), assumptions[:3])
