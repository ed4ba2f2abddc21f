"""The cost of an ``adaptive`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage, plan_poisson
from ..cost import runs_plan
from ..prices import poisson_run_seconds

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of an ``adaptive`` study: per estimator the adaptive loop's levels, from the base
    mesh's unknowns up to ``max_dofs`` (Dörfler marking with ``theta`` grows them by about
    ``1 + 0.8 theta`` per level: 1.4 at the usual 0.5, measured on the bundled studies), and
    the uniform refinements (4x) up to the same size; each level one assembly, solve, error
    estimate and error evaluation, plus the loop's fixed cost per level (marking, bisection)."""
    from ...case.cost import geometry_domain
    from ...cost import load_constants, msh_triangle_count, predict_triangles
    from ...solvers.registry import priced_names
    from ..problem import study_problem

    d = study.spec
    mesh = study_problem(study, need_exact=False).case.spec.mesh
    if mesh.file is not None:
        triangles = float(msh_triangle_count(mesh.file)[0])
    else:
        _, area, length = geometry_domain(mesh.geometry, dict(mesh.params))
        triangles = predict_triangles(area, length, float(d.h0 or mesh.h))
    start, max_dofs = max(triangles / 2.0, 4.0), float(d.max_dofs)
    solver = study.solvers[0]
    fixed = load_constants()["seconds"].get("adaptive_level_fixed", 0.0)

    def level_seconds(dofs: float) -> float:
        method, preconditioner = priced_names(solver.method, solver.preconditioner)
        p = plan_poisson(triangles=2.0 * dofs, method=method, rtol=solver.rtol,
                         preconditioner=preconditioner, outputs=(), errors=True)
        return (poisson_run_seconds(2.0 * dofs, solver) + p.stage("estimate").seconds
                + p.stage("errors").seconds + p.stage("quality").seconds + fixed)

    def sweep(growth: float, max_levels: int) -> tuple[float, int]:
        seconds, levels, dofs = 0.0, 0, start
        while dofs <= max_dofs and levels < max_levels:
            seconds, levels, dofs = seconds + level_seconds(dofs), levels + 1, dofs * growth
        return seconds, levels

    adaptive, levels = sweep(1.0 + 0.8 * d.theta, d.max_levels)
    uniform, uniform_levels = sweep(4.0, d.max_levels)
    stages = [Stage(f"adaptive {name}", adaptive, 0.0, detail=f"~{levels} levels")
              for name in d.estimators]
    stages.append(Stage("uniform", uniform, 0.0,
                        detail=f"{uniform_levels} levels up to {max_dofs:,.0f} unknowns"))
    return runs_plan(study, stages, levels * len(d.estimators) + uniform_levels, [
        f"from ~{start:,.0f} unknowns; adaptive levels grow the unknowns by 1 + 0.8 theta, "
        "uniform ones 4x; each level costed by the Poisson model (assembly, solve, error "
        "estimate, errors) plus a fixed cost per level (femkit/cost/constants.json)"])
