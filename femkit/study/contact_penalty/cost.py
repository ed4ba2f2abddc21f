"""The cost of a ``contact_penalty`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import SCENE_FREE_ITERATIONS, Plan, Stage, contact_stage
from ..cost import runs_plan

__all__ = ["plan"]

#: Seconds per Newton step per cloth vertex (penalty runs; barrier runs priced by the scene
#: plan's contact stage, :func:`femkit.cost.contact_stage`).
SECONDS_PER_NODE_STEP = 2e-4


def plan(study) -> Plan:
    """One stage per penalty stiffness and one for barrier contact."""
    s = study.spec
    steps = max(1, round(s.t_end / s.dt))
    nodes = s.n * s.n
    penalty = steps * nodes * SECONDS_PER_NODE_STEP
    stages = [Stage(f"penalty k={k:g}", penalty, 0.0) for k in s.stiffnesses]
    barrier = contact_stage(steps, 2.0 * nodes + 2, nodes * SECONDS_PER_NODE_STEP
                            / SCENE_FREE_ITERATIONS, SCENE_FREE_ITERATIONS)
    stages.append(Stage("barrier", penalty + barrier.seconds, 0.0, detail=barrier.detail))
    return runs_plan(study, stages, len(stages), ["newton for every run, the same dt"])
