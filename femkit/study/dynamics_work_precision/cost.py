"""The cost of a ``dynamics_work_precision`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan
from ..prices import steps_seconds

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``dynamics_work_precision`` study: every (integrator, dt) run ``repeats``
    times, the reference runs (when not analytic) and the warm-up, priced per step."""
    d = study.spec
    nodes, springs = d.scene.size
    t_end, dts, ref = d.scene.t_end, d.dts, d.reference
    stages = []
    if not (d.scene.analytic and ref.analytic):
        every = max(1, int(round(max(dts) / ref.dt)))
        steps = t_end / (max(dts) / every) * (1.5 if every % 2 == 0 else 3.0)  # and its check run
        stages.append(Stage("reference", steps_seconds(steps, nodes=nodes, springs=springs), 0.0,
                            detail=f"{ref.integrator}, {steps:,.0f} steps"))
    for spec in study.integrators:
        implicit = bool(spec.build().implicit)
        steps = sum(t_end / dt for dt in dts) * d.repeats
        steps += 20 if d.warmup else 0
        stages.append(Stage(spec.label, steps_seconds(steps, nodes=nodes, springs=springs,
                                                      implicit=implicit), 0.0,
                            detail=f"{len(dts)} dt x {d.repeats} repeat(s), {steps:,.0f} steps"))
    runs = len(study.integrators) * len(dts)
    return runs_plan(study, stages, runs, [
        f"{nodes} nodes, {springs} springs; seconds per step from the scene model "
        "(femkit/cost/constants.json, scene.step_seconds_*)"])
