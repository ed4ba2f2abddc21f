"""The cost of an ``element_work_precision`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage

__all__ = ["plan"]


def plan(study) -> Plan:
    """One stage per series: its levels' runs, each priced as a Poisson run
    (:func:`femkit.study.prices.poisson_run_seconds`, ``repeats`` times) on the triangles of its
    level; an element of degree ``p`` on level ``k`` as P1 on level ``k + p - 1`` (the same
    unknowns: P2's nodes are the vertices of the refined mesh), tetrahedra as 8 children per
    refinement; an adaptive series as uniform runs up to its ``max_dofs``. A solid base case:
    each run priced by the solid kind's plan of the case at the level's ``h``."""
    from ...case.cost import geometry_domain, tets_per_h3
    from ...cost import msh_triangle_count
    from ...elements import get_element
    from ..cost import runs_plan
    from ..prices import poisson_run_seconds
    from ..problem import study_problem

    d = study.spec
    if d.reference is not None:
        return _solid_plan(study)
    case = study_problem(study).case
    mesh = case.spec.mesh
    if mesh.file is not None:
        dim, cells = 2, float(msh_triangle_count(mesh.file)[0])
    else:
        dim, size, _ = geometry_domain(mesh.geometry, dict(mesh.params))
        cells = size / d.h0 ** 2 * 2.33 if dim == 2 else tets_per_h3(mesh.geometry) * size / d.h0 ** 3
    cells *= (2 ** dim) ** mesh.refine
    from ...case.specs import solver_spec

    solver = solver_spec(d.solver, "solver")
    stages = []
    for element, count in zip(d.elements, d.counts):
        p = get_element(element, dim).degree
        seconds = sum(d.repeats * poisson_run_seconds(cells * (2 ** dim) ** (k + p - 1) * (1 if dim == 2 else 2),
                                                      solver) for k in range(count))
        stages.append(Stage(element, seconds, 0.0, detail=f"{count} levels x {d.repeats} repeat(s)"))
    runs = sum(d.counts)
    if d.adaptive is not None:
        # a P1 mesh of max_dofs nodes has ~2 max_dofs triangles (2D); the loop's levels sum to ~3x its last
        for element in d.adaptive["elements"]:
            seconds = 3.0 * poisson_run_seconds(2.0 * d.adaptive["max_dofs"] * (1 if dim == 2 else 3), solver)
            stages.append(Stage(f"{element} adaptive", seconds, 0.0, detail=f"up to {d.adaptive['max_dofs']:,} dofs"))
        runs += len(d.adaptive["elements"])
    return runs_plan(study, stages, runs, [
        "each run priced as a P1 Poisson run with the same unknowns (femkit.cost.plan_poisson); "
        "a generated 2D mesh has ~2.33 triangles per h^2 of area; memory not modelled here"])


def _solid_plan(study) -> Plan:
    """Each (element, level) run priced by the solid kind's plan of the base case at its ``h``."""
    from ...kinds import KINDS
    from ..cost import runs_plan
    from ..spec import load_base_case

    d = study.spec
    stages, assumptions = [], []
    for element, count in zip(d.elements, d.counts):
        seconds = 0.0
        for k in range(count):
            case = load_base_case(study, mesh={"h": d.h0 / 2 ** k}, element=element)[1]
            p = KINDS.get("solid", "problem").plan(case, measure=False)
            seconds += d.repeats * p.seconds
            assumptions = p.assumptions
        stages.append(Stage(element, seconds, 0.0, detail=f"{count} levels x {d.repeats} repeat(s)"))
    return runs_plan(study, stages, sum(d.counts), assumptions[:3])
