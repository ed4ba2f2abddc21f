"""The cost of a study before it runs (``femkit study STUDY --dry-run``, budgets).

Every built-in study kind's plan sums the runs its sweep will do, each priced by the cost
model (:mod:`femkit.cost`) from numbers: a convergence study per mesh level (every solver and
quadrature rule ``repeats`` times, the scikit-fem reference and nested-iteration runs; the peak
memory is the largest run's plus the meshes of every level, which the sweep keeps), a
work-precision study per integrator (its steps over every dt), the stress suite per stress
case (each type's ``price`` in :data:`femkit.study.stability.STRESS_CASES`), the adaptive
study per refinement level, the cloth study per method setting. Library imports are counted
once (each sweep's warm-up pays them). Each plan is its kind's ``plan``; ``femkit study
--dry-run`` prints it and the default time budget (:data:`femkit.cost.DEFAULT_TIME_BUDGET`)
is checked against it.
"""

from __future__ import annotations

from ..cost import Plan, Stage, plan_poisson
from .prices import poisson_run_seconds, steps_seconds

__all__ = ["plan_study", "plan_poisson_study", "plan_dynamics_study", "plan_stability_study",
           "plan_adaptive_study", "plan_cloth_study", "plan_springs_study", "poisson_run_seconds",
           "steps_seconds"]



def plan_poisson_study(study) -> Plan:
    """The plan of a ``poisson_convergence`` study: the runs :func:`femkit.study.poisson.
    run_poisson_study` does, each priced by :func:`femkit.cost.plan_poisson` on its level.

    Per level: the mesh (generated once, then refined); per rule ``repeats`` assemblies and
    boundary reductions; per rule and solver ``repeats`` setups and solves and one error
    evaluation; the scikit-fem reference (``repeats`` assemblies and AMG-CG solves); the
    nested-iteration runs (an assembly, a direct solve and ``repeats`` solves per (P)CG solver).
    Library imports are counted once (the warm-up pass), not per run.
    """
    from ..case.cost import geometry_domain
    from ..cost import load_constants, msh_triangle_count
    from .problem import study_problem

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


def plan_study(study, *, speed: float = 1.0) -> Plan:
    """The plan of any study, through its kind (``KINDS[study.kind].plan``), its seconds
    multiplied by ``speed`` (:func:`femkit.cost.machine_speed`: this machine against the one the
    constants were fitted on); a kind without a cost model gets a plan that says so."""
    from ..kinds import KINDS

    kind = KINDS.get(study.kind, "kind")
    if kind.plan is not None:
        plan = kind.plan(study)
        if speed != 1.0:
            for stage in plan.stages:
                stage.seconds *= speed
            plan.assumptions.append(f"seconds scaled by this machine's speed now (x{speed:.2f})")
        return plan
    from ..cost import load_constants

    return Plan("study", f"{study.name}: {study.kind}", {}, [],
                load_constants()["bytes"]["baseline"], assumptions=[f"no cost model for study kind {study.kind!r} yet: only its "
                             "mesh sizes and time steps bound the cost"])


def runs_plan(study, stages: list, runs: int, assumptions: list) -> Plan:
    """A study's plan from its priced stages (one per group of runs)."""
    from ..cost import load_constants

    return Plan("study", f"{study.name}: {study.kind}, {runs} runs", {"runs": runs}, stages,
                load_constants()["bytes"]["baseline"], assumptions)


def plan_dynamics_study(study) -> Plan:
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


def plan_stability_study(study) -> Plan:
    """The plan of a ``stability`` study: each stress case priced by its type's ``price``
    (:data:`femkit.study.stability.STRESS_CASES`), plus the warm-up."""
    from .stability import STRESS_CASES, load_cases

    quick_n = 16 if study.quick else 64
    stages, runs = [], 0
    for case in load_cases(study):
        price = STRESS_CASES.get(case["type"]).price
        seconds, n = price(case, study, quick_n) if price is not None else (0.0, 0)
        runs += n
        stages.append(Stage(case["name"], seconds, 0.0, detail=f"{case['type']}, {n} run(s)"))
    return runs_plan(study, stages, runs, [
        "Poisson cases: the cost model's assembly, setup and solve on each case's mesh at the "
        "iteration counts of well-conditioned problems (ill-conditioned ones iterate longer); "
        "dynamics cases: the scene model's seconds per step"])


def plan_adaptive_study(study) -> Plan:
    """The plan of an ``adaptive`` study: per estimator the adaptive loop's levels, from the base
    mesh's unknowns up to ``max_dofs`` (Dörfler marking with ``theta`` grows them by about
    ``1 + 0.8 theta`` per level: 1.4 at the usual 0.5, measured on the bundled studies), and
    the uniform refinements (4x) up to the same size; each level one assembly, solve, error
    estimate and error evaluation, plus the loop's fixed cost per level (marking, bisection)."""
    from ..case.cost import geometry_domain
    from ..cost import load_constants, msh_triangle_count, predict_triangles
    from .problem import study_problem

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
        p = plan_poisson(triangles=2.0 * dofs, method=solver.method, rtol=solver.rtol,
                         preconditioner=solver.preconditioner, outputs=(), errors=True)
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


def plan_cloth_study(study) -> Plan:
    """The plan of a ``cloth_work_precision`` study: per scene, every method setting's frames
    (one implicit step each, ``iterations`` inner solves), the implicit-Euler reference solved
    to its tolerance and the RK4 trajectory reference at ``substeps`` steps per frame."""
    from ..case.scene.systems import system_size
    from .cloth import _scene_case

    d = study.spec
    frames, substeps = d.frames, d.reference.substeps
    stages, runs = [], 0
    for path in d.scenes:
        case = _scene_case(study, path)
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


def plan_solid_load_study(study) -> Plan:
    """The plan of a ``solid_load`` study: each material's run priced by the solid kind's plan
    (:func:`femkit.case.solid.cost.plan_solid_case`) of the case it runs."""
    from ..kinds import KINDS
    from .solid_load import material_cases

    stages, assumptions = [], []
    for name, case in material_cases(study):
        plan = KINDS.get("solid", "problem").plan(case, measure=False)
        stages.append(Stage(name, plan.seconds, plan.peak_bytes - plan.baseline_bytes,
                            detail=f"{study.spec.load_steps} load steps"))
        assumptions = plan.assumptions
    return runs_plan(study, stages, len(stages), assumptions[:3])


def plan_springs_study(study) -> Plan:
    """The plan of a ``springs_vs_elements`` study: per scene, every method on every mesh size
    (``repeats`` times, triangles from the geometry's measure, springs ~1.5 per triangle, two
    layouts' worth for ``edges_cross``) and the reference on its finer mesh, each priced as
    implicit steps (:func:`femkit.study.prices.implicit_run_seconds`)."""
    from ..case.cost import geometry_domain
    from ..cost import predict_triangles
    from .prices import implicit_run_seconds
    from .springs_scenes import SVSE_SCENES

    d = study.spec
    stages, runs = [], 0
    for name, p in d.scenes.items():
        geo, params = SVSE_SCENES.get(name).geometry(p)
        _, area, length = geometry_domain(geo, params)
        steps = float(p["t_end"]) / float(p["dt"])

        def price(method, h):
            tri = predict_triangles(area, length, h)
            nodes = tri / 2.0 + length / h / 2.0
            parts = tri if not method.springs else 1.5 * tri * (2 if method.layout ==
                                                                 "edges_cross" else 1)
            return implicit_run_seconds(steps, nodes=nodes, parts=parts,
                                        integrator=method.integrator.method,
                                        elements=not method.springs)

        seconds = price(d.reference, float(p["reference_h"]))
        seconds += sum(d.repeats * price(m, float(h)) for m in d.methods for h in p["h"])
        if d.warmup:
            seconds += sum(price(m, max(p["h"])) * 2.0 / steps for m in d.methods)
        n = len(d.methods) * len(p["h"]) + 1
        runs += n
        stages.append(Stage(name, seconds, 0.0, detail=f"{len(d.methods)} methods x "
                            f"{len(p['h'])} mesh sizes + reference at h {p['reference_h']:g}, "
                            f"{steps:,.0f} steps each"))
    return runs_plan(study, stages, runs, [
        "triangles from the geometry's measure (gmsh); each run priced as implicit steps of the "
        "scene model times the integrator's solves per step (femkit/study/prices.py); an "
        "order of magnitude"])
