"""The cost of a ``cloth_work_precision`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan
from ..prices import steps_seconds
from .spec import scene_case

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``cloth_work_precision`` study: per scene, every method setting's frames
    (one implicit step each, ``iterations`` inner solves), the implicit-Euler reference solved
    to its tolerance and the RK4 trajectory reference at ``substeps`` steps per frame."""
    from ...case.scene.systems import system_size

    d = study.spec
    frames, substeps = d.frames, d.reference.substeps
    stages, runs = [], 0
    for path in d.scenes:
        case = scene_case(study, path)
        size = system_size(case.spec.system)
        nodes, springs, dim = size.nodes, size.springs, size.dim
        solves = 0
        for m in d.methods:
            its = list(m.get("iterations") or [1])
            runs += len(its)
            solves += sum(its)
        solves += 40  # the reference solve to tol ~ tens of local/global iterations per frame
        implicit = steps_seconds(solves * frames, nodes=nodes, springs=springs, dim=dim, implicit=True)
        explicit = steps_seconds(frames * substeps * 4, nodes=nodes, springs=springs, dim=dim)
        stages.append(Stage(case.name, implicit + explicit, 0.0,
                            detail=f"{nodes:,} nodes, {frames} frames, {solves} solves per frame"))
    return runs_plan(study, stages, runs, [
        "one implicit solve per inner iteration (implicit per-spring constant), the reference's "
        "solve ~40 iterations per frame, RK4 = 4 explicit steps per substep"])
