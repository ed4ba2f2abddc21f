"""The cost of a ``poisson_convergence`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage, plan_poisson

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``poisson_convergence`` study: the runs :func:`femkit.study.
    poisson_convergence.run.run` does, each priced by :func:`femkit.cost.plan_poisson` on its level.

    Per level: the mesh (generated once, then refined); per rule ``repeats`` assemblies and
    boundary reductions; per rule and solver ``repeats`` setups and solves and one error
    evaluation; the scikit-fem reference (``repeats`` assemblies and AMG-CG solves); the
    nested-iteration runs (an assembly, a direct solve and ``repeats`` solves per (P)CG solver).
    Library imports are counted once (the warm-up pass), not per run.
    """
    from ...case.cost import geometry_domain
    from ...cost import load_constants, msh_triangle_count
    from ...solvers.registry import priced_names
    from ..problem import study_problem

    case = study_problem(study).case
    mesh = case.spec.mesh
    d = study.spec
    repeats, rules = d.repeats, list(d.quadrature)
    reference = d.reference == "scikit-fem"
    nested = d.stop_fraction is not None and d.levels.nested
    c = load_constants()["seconds"]
    imports = c["pyamg_import"]
    stages, peak, mesh_bytes, largest, p = [], 0.0, 0.0, 0.0, None
    amg = False
    for level, (h, k) in enumerate(d.levels.sizes()):
        if mesh.file is not None:
            where = dict(triangles=msh_triangle_count(mesh.file)[0])
        else:
            _, area, length = geometry_domain(mesh.geometry, dict(mesh.params))
            where = dict(area=area, line_length=length, h=h, name=mesh.geometry,
                         params=dict(mesh.params))
        where["refine"] = k + mesh.refine

        def run(method, preconditioner="none", rtol=None):
            method, preconditioner = priced_names(method, preconditioner)
            return plan_poisson(method=method, preconditioner=preconditioner, rtol=rtol,
                                outputs=(), errors=True, **where)

        def secs(plan, *names) -> float:
            return sum(plan.stage(n).seconds for n in names)

        def solve_secs(plan) -> float:
            # the model's setup includes pyamg's import (AMG, and multigrid's coarse levels);
            # a study pays it once, in its warm-up (where the import is not included, the
            # setup exceeds it only on meshes where the difference is negligible)
            setup = plan.stage("setup").seconds
            return max(setup - imports, 0.0) + plan.stage("solve").seconds

        level_peak, seconds = 0.0, 0.0
        for s in study.solvers:
            p = run(s.method, s.preconditioner, s.rtol)
            amg = amg or p.stage("setup").seconds >= imports
            seconds += len(rules) * (repeats * solve_secs(p) + secs(p, "errors"))
            if nested and s.method in ("cg", "pcg"):
                seconds += repeats * solve_secs(p)
            level_peak = max(level_peak, max(st.peak_bytes for st in p.stages))
        seconds += len(rules) * repeats * secs(p, "assembly", "boundary")
        if nested:  # the nested runs' own assembly and the direct solve of the exact discrete u
            seconds += secs(p, "assembly", "boundary") + solve_secs(run("direct"))
        if reference:
            ref = run("pcg", "amg_sa", study.solvers[0].rtol)
            amg = True
            seconds += repeats * (secs(ref, "assembly", "boundary") + solve_secs(ref))
            seconds += secs(ref, "errors")
        seconds += secs(p, "mesh") if level == 0 else secs(p, "refine") / 4 ** (k - 1) / 4 * 3
        seconds += secs(p, "quality")
        triangles = p.sizes["triangles"]
        largest = max(largest, triangles)
        peak = max(peak, mesh_bytes + level_peak)
        mesh_bytes += 40.0 * triangles  # points, triangles and tags of the level, kept
        stages.append(Stage(f"level {level}", seconds, mesh_bytes + level_peak,
                            detail=f"{triangles:,.0f} triangles, {len(study.solvers)} solver(s) x "
                                   f"{len(rules)} rule(s) x {repeats} repeat(s)"
                                   + (" + reference" if reference else "")
                                   + (" + nested" if nested else "")))
    if amg or reference:
        once = (imports if amg else 0.0) + (c.get("skfem_import", 0.0) if reference else 0.0)
        stages.insert(0, Stage("imports", once, 0.0, detail=", ".join(
            n for n, on in (("pyamg", amg), ("scikit-fem", reference)) if on) + ", once"))
    runs = len(d.levels.sizes()) * (len(study.solvers) * len(rules) + int(reference))
    plan = Plan("study", f"{study.name}: poisson_convergence, {len(d.levels.sizes())} levels",
                {"runs": runs, "triangles": largest}, stages, p.baseline_bytes,
                p.assumptions[:2] + [
                    "the meshes of every level stay in memory (~40 bytes per triangle); each "
                    "level's refinement costs 3/4 of the model's refine stage (the last step)"])
    return plan
