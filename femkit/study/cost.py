"""The cost of a study before it runs (``femkit study STUDY --dry-run``, budgets).

A convergence study's plan has one stage per mesh level: every solver and quadrature rule,
``repeats`` times, on that level's mesh (:func:`femkit.cost.plan_poisson` per run); the
peak memory is the largest run's plus the meshes of every level (the sweep keeps them all).
It is that kind's ``plan``; other study kinds have no cost model yet: their plan says so.
"""

from __future__ import annotations

from ..cost import Plan, Stage, plan_poisson

__all__ = ["plan_study"]


def _levels(study) -> list[tuple[float, int]]:
    """``(h, refinements)`` of each mesh level, as :func:`femkit.study.poisson._meshes` builds them."""
    lv = study.data["levels"]
    if "h" in lv:
        hs = list(lv["h"])[: lv["max_level"] + 1] if "max_level" in lv else list(lv["h"])
        return [(float(h), 0) for h in hs]
    count = lv["count"] if "max_level" not in lv else min(lv["count"], lv["max_level"] + 1)
    return [(float(lv["h0"]), k) for k in range(count)]


def plan_poisson_study(study) -> Plan:
    """The plan of a ``poisson_convergence`` study."""
    from ..case.cost import geometry_domain
    from ..cost import msh_triangle_count
    from .problem import study_problem

    case = study_problem(study).case
    spec = case.data["mesh"]
    d = study.data
    repeats, rules = int(d["repeats"]), list(d["quadrature"])
    stages, peak, mesh_bytes, largest = [], 0.0, 0.0, 0.0
    for level, (h, k) in enumerate(_levels(study)):
        if "file" in spec:
            where = dict(triangles=msh_triangle_count(spec["file"])[0])
        else:
            _, area, length = geometry_domain(spec["geometry"], spec.get("params"))
            where = dict(area=area, line_length=length, h=h, name=spec["geometry"],
                         params=spec.get("params"))
        where["refine"] = k + spec.get("refine", 0)
        seconds, level_peak = 0.0, 0.0
        for s in study.solvers:
            p = plan_poisson(method=s.method, preconditioner=s.preconditioner, rtol=s.rtol,
                             outputs=(), errors=True, **where)
            per_run = sum(st.seconds for st in p.stages if st.name != "mesh")
            seconds += per_run * repeats * len(rules)
            level_peak = max(level_peak, max(st.peak_bytes for st in p.stages))
        mesh = p.stage("mesh")
        seconds += mesh.seconds
        triangles = p.sizes["triangles"]
        largest = max(largest, triangles)
        peak = max(peak, mesh_bytes + level_peak)
        mesh_bytes += 40.0 * triangles  # points, triangles and tags of the level, kept
        stages.append(Stage(f"level {level}", seconds, mesh_bytes + level_peak,
                            detail=f"{triangles:,.0f} triangles, {len(study.solvers)} solver(s) x "
                                   f"{len(rules)} rule(s) x {repeats} repeat(s)"))
    plan = Plan("study", f"{study.name}: poisson_convergence, {len(stages)} levels",
                {"runs": len(stages) * len(study.solvers) * len(rules), "triangles": largest},
                stages, p.baseline_bytes, p.assumptions[:2] + [
                    "the meshes of every level stay in memory (~40 bytes per triangle); the "
                    "scikit-fem reference and nested-iteration runs are not included"])
    return plan


def plan_study(study) -> Plan:
    """The plan of any study, through its kind (``KINDS[study.kind].plan``); a kind without a
    cost model gets a plan that says so."""
    from ..case.kinds import KINDS

    kind = KINDS.get(study.kind, "kind")
    if kind.plan is not None:
        return kind.plan(study)
    from ..cost import load_constants

    return Plan("study", f"{study.name}: {study.kind}", {}, [],
                load_constants()["bytes"]["baseline"], assumptions=[f"no cost model for study kind {study.kind!r} yet: only its "
                             "mesh sizes and time steps bound the cost"])
