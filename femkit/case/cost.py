"""The cost of a case or scene file before it runs: its plan, the budget checks, the stop flag.

The cost model (:mod:`femkit.cost`) takes numbers; this module turns a case into them and runs
the checks, so no library layer plans anything:

* :func:`geometry_domain` reads a geometry's area and line length from its entry in
  :data:`femkit.mesh.GEOMETRIES` (one registration declares a geometry and its measure);
* :func:`check_mesh_fits` is the memory guard the runners call before generating or refining a
  mesh (:func:`femkit.mesh.generate`, :func:`femkit.mesh.refine` do not check themselves): a
  mesh whose predicted memory exceeds the available memory is refused before gmsh or numpy
  start (:class:`~femkit.errors.BudgetExceededError`, one line with the ``h`` that fits);
* :func:`measure_step_seconds` times a scene's first batch of steps (what ``plan_scene`` is
  given as ``step_seconds``);
* :func:`plan_poisson_case` and :func:`plan_scene_case` are the plans of the two problem
  kinds (``KINDS[...].plan``); :mod:`femkit.case.budget` checks a case's plan against its
  limits before it runs.

Nothing here imports another module of ``femkit.case``: the runners import this module (the
guard), so it stays below them.
"""

from __future__ import annotations

import math
import time

from ..cost import Plan, check_budget, plan_mesh, plan_poisson, plan_scene

__all__ = ["plan_poisson_case", "plan_scene_case", "geometry_domain", "case_dimension",
           "check_mesh_fits",
           "check_scene_fits", "measure_step_seconds", "OVERRIDE"]

#: How a user overrides a refused budget (quoted in the one-line refusal).
OVERRIDE = "--force"


def geometry_domain(geometry: str, params: dict | None = None) -> tuple[int, float, float]:
    """``(dim, measure, line_measure)`` of a registered geometry with its parameters.

    In 2D the area and the length of every mesh line (see :mod:`femkit.mesh.geometries`).

    Raises
    ------
    UnknownNameError
        Not a registered geometry (the message lists them).
    InputError
        Parameters that do not fit the geometry or give no positive measure.
    """
    from ..mesh.geometries import GEOMETRIES

    entry = GEOMETRIES.get(geometry)
    size, lines = entry.measures(params)
    return entry.dim, size, lines


def case_dimension(case) -> int | None:
    """The dimension of a Poisson ``case``'s mesh before it is built, as the plan reads it (a
    geometry's entry, a ``.msh`` file's header); None when the input cannot be read (the mesh
    stage reports why)."""
    from ..cost import msh_has_volume
    from ..errors import FemkitError

    mesh = case.spec.mesh
    try:
        if mesh.file is not None:
            return 3 if msh_has_volume(mesh.file) else 2
        return geometry_domain(mesh.geometry, dict(mesh.params))[0]
    except (FemkitError, OSError):
        return None


#: Tetrahedra gmsh makes per ``h^3`` of volume (unit cube: 1,140 at h = 0.2, 8,617 at 0.1).
TETS_PER_H3 = 9.0
#: Geometries whose tetrahedra are counted exactly: Kuhn cubes of side ``h``, each cut into 6
#: tetrahedra (``kuhn_cube`` h = 1/4: 384), so ``6 V / h^3``.
EXACT_TETS_PER_H3 = {"kuhn_cube": 6.0, "kuhn_fichera": 6.0}


def tets_per_h3(geometry: str) -> float:
    """Tetrahedra per ``h^3`` of volume of a generated 3D geometry: exact for the Kuhn
    geometries (:data:`EXACT_TETS_PER_H3`), gmsh's measured density otherwise."""
    return EXACT_TETS_PER_H3.get(geometry, TETS_PER_H3)
#: One tetrahedron in triangles of the 2D model (the stiffness entries of a cell, 4 x 4 against
#: 3 x 3): the time of a tetrahedral run's stages, and the memory of the stages the 3D memory
#: model has no law for (:mod:`femkit.cost.tetrahedra`).
TET_AS_TRIANGLES = 16.0 / 9.0


def _in_3d(plan: Plan, tets: float, refine: int, method: str) -> Plan:
    """``plan`` (priced in triangle equivalents) with the memory of its stages from the 3D laws
    (:func:`femkit.cost.tetrahedra.stage_bytes`) for ``tets`` cells before ``refine``
    refinements: the mesh stage (generation or reading) holds the coarse mesh, every later
    stage the refined one; a stage without a 3D law keeps its price."""
    from ..cost import load_constants
    from ..cost.tetrahedra import stage_bytes

    c = load_constants()
    for st in plan.stages:
        coarse = st.name == "mesh"
        price = stage_bytes(st.name, tets if coarse else tets * 8.0 ** refine, method, c)
        if price is not None:
            st.peak_bytes = max(st.peak_bytes, price) if coarse else price
    return plan


def check_mesh_fits(*, geometry: str | None = None, h: float | None = None,
                    params: dict | None = None, triangles: float | None = None, refine: int = 0,
                    dim: int = 2, force: bool = False, override: str = OVERRIDE,
                    available: float | None = None) -> None:
    """Refuse a mesh generation (``geometry``, ``h``, ``params``) or a refinement of a mesh of
    ``triangles`` cells of dimension ``dim`` ``refine`` times whose predicted memory exceeds
    the available memory; call it before :func:`femkit.mesh.generate` /
    :func:`femkit.mesh.refine`.

    Only the mesh stages are planned (:func:`femkit.cost.plan_mesh`, a triangle model). A
    tetrahedral mesh (a generated one at :func:`tets_per_h3` tetrahedra per ``h^3`` of volume;
    8 children per refinement, Bey's red refinement) is priced by the 3D laws of
    :mod:`femkit.cost.tetrahedra` (the refined hierarchy, its numbering and quality). ``force``
    skips the check; ``available`` replaces the machine's available memory (bytes).

    Raises
    ------
    BudgetExceededError
        The mesh alone would not fit in the available memory.
    """
    if force:
        return
    if triangles is None:
        dim, size, length = geometry_domain(geometry, params)
        if dim == 2:
            plan = plan_mesh(area=size, line_length=length, h=h, refine=refine, name=geometry,
                             params=params)
            check_budget(plan, override=override, available=available)
            return
        triangles = tets_per_h3(geometry) * size / float(h) ** 3
    if dim == 3:  # 8^k tetrahedra after k refinements = (2^k cells) x 4^k in the 2D model
        plan = _in_3d(plan_mesh(triangles=TET_AS_TRIANGLES * triangles * 2.0 ** refine,
                                refine=refine), triangles, refine, "")
    else:
        plan = plan_mesh(triangles=triangles, refine=refine)
    check_budget(plan, override=override, available=available)


def measure_step_seconds(system, integrator, dt: float, *, ctx=None, batch: int = 20,
                         max_seconds: float = 1.0, **integrator_options) -> float:
    """Seconds per step of ``integrator`` on ``system``, timed on a first batch of steps.

    One warm-up step first (imports, symbolic factorisations, caches of ``ctx``: paid once per
    run, not per step), then up to ``batch`` steps (stopping early after ``max_seconds``) from
    the system's initial state without stability checks.
    """
    from ..dynamics.integrators import StepContext
    from ..dynamics.simulate import simulate

    ctx = ctx if ctx is not None else StepContext()
    quiet = dict(check_stability=False, energy_growth_limit=math.inf, **integrator_options)
    simulate(system, integrator, dt, dt, ctx=ctx, **quiet)
    budget_end = time.perf_counter() + float(max_seconds)
    t0 = time.perf_counter()
    traj = simulate(system, integrator, dt, batch * dt, ctx=ctx, record_every=batch,
                    stop=lambda: time.perf_counter() > budget_end, **quiet)
    return (time.perf_counter() - t0) / max(traj.steps, 1)


def plan_poisson_case(case, *, measure: bool = True) -> Plan:
    """The plan of a Poisson case (from ``case.spec``); with ``measure`` its seconds are scaled
    by this machine's speed now (:func:`femkit.cost.machine_speed`, ~0.25 s of probing)."""
    from ..cost import machine_speed, msh_has_volume, msh_triangle_count

    spec = case.spec
    mesh, out = spec.mesh, spec.output
    outputs = tuple(k for k, on in (("vtu", out.vtu), ("xdmf", out.xdmf), ("png", out.plot)) if on)
    common = dict(refine=mesh.refine, method=case.solver.method,
                  speed=machine_speed() if measure else 1.0,
                  preconditioner=case.solver.preconditioner, rtol=case.solver.rtol,
                  outputs=outputs, errors="exact.u" in case.functions)
    if mesh.file is not None:
        cells, how = msh_triangle_count(mesh.file)
        if msh_has_volume(mesh.file):
            plan = _tetrahedral_plan(cells, f"{cells:,} elements in {mesh.file} (from {how})",
                                     f"mesh file ({cells:,} elements)", common, generated=False)
        else:
            plan = plan_poisson(triangles=cells, **common)
            plan.assumptions.insert(0, f"{cells:,} triangles in {mesh.file} (from {how})")
    else:
        params = dict(mesh.params)
        dim, size, length = geometry_domain(mesh.geometry, params)
        if dim == 3:
            density = tets_per_h3(mesh.geometry)
            tets = density * size / float(mesh.h) ** 3
            plan = _tetrahedral_plan(tets, f"{tets:,.0f} tetrahedra: {density:g} per h^3 of "
                                     f"volume {size:g}", f"{mesh.geometry} h={mesh.h:g}", common,
                                     generated=True)
        else:
            plan = plan_poisson(area=size, line_length=length, h=mesh.h, name=mesh.geometry,
                                params=params, **common)
    plan.title = f"{case.name}: {plan.title}"
    if spec.adaptive:
        plan.assumptions.append("adaptive refinement: only the first level is costed; the "
                                "adaptive budgets (max_dofs, max_time, max_levels) bound the rest")
    return plan


def _tetrahedral_plan(tets: float, source: str, title: str, common: dict, *,
                     generated: bool) -> Plan:
    """The plan of a tetrahedral Poisson run of ``tets`` cells before refinement (``generated``
    by gmsh, else read from a file): memory by the 3D laws (:mod:`femkit.cost.tetrahedra`, as
    :func:`check_mesh_fits` with ``dim=3``), time and the stages without a 3D law as
    :data:`TET_AS_TRIANGLES` triangles of the 2D model per tetrahedron; 8 children per
    refinement (Bey 1995); sizes and the stages' words in tetrahedra."""
    import re

    k = common["refine"]
    plan = _in_3d(plan_poisson(triangles=TET_AS_TRIANGLES * tets * 2.0 ** k, **common), tets, k,
                  common["method"])
    rest = {key: v for key, v in plan.sizes.items() if key != "triangles"}
    plan.sizes = {"tetrahedra": tets * 8.0 ** k, **rest}
    for st in plan.stages:  # the triangle equivalents are the model's, not the run's words
        if st.name == "mesh":
            st.detail = f"gmsh, ~{tets:,.0f} tetrahedra" if generated else f"read {tets:,.0f} tetrahedra"
        st.detail = re.sub(r"-> [\d,]+ triangles", f"-> {tets * 8.0 ** k:,.0f} tetrahedra", st.detail)
    plan.title = title
    plan.assumptions[0] = (f"{source}, x8 per refinement; memory per tetrahedron calibrated on "
                           "tetrahedral runs (femkit/cost/tetrahedra.py), time and the stages "
                           f"without a 3D calibration as {TET_AS_TRIANGLES:.3g} triangles of the "
                           "2D model (the 4 x 4 stiffness block against 3 x 3)")
    return plan


def plan_scene_case(case, size, *, build=None, measure: bool = True) -> Plan:
    """The plan of a scene from ``case.spec`` (time grid, cadence, outputs) and ``size`` (a
    :class:`femkit.case.scene.systems.SystemSize`: nodes, springs, dim and the mesh it needs,
    counted from the file's numbers), before anything is allocated.

    With ``measure`` (and ``build() -> (system, integrator, ctx)``) the memory is checked first
    (a scene that cannot fit is refused before it is built:
    :class:`~femkit.errors.BudgetExceededError`, unless ``case.run_options["force"]``), then the
    system is built and its seconds per step timed on a first batch of steps (at most 20 steps
    or 1 s, :func:`measure_step_seconds`). ``size`` None (a system type that cannot count
    itself) needs ``build``: the plan is then made from the built system.
    """
    spec = case.spec
    method, implicit = spec.integrator.method, _implicit(spec.integrator)
    system = integrator = ctx = None
    if size is None:
        if build is None:
            return Plan("scene", f"{case.name}: {method}", {}, [],
                        assumptions=["no size model for this system type: the run is not costed"])
        system, integrator, ctx = build()
        nodes, springs, dim, mesh = system.n, system.n_springs, system.dim, None
    else:
        nodes, springs, dim, mesh = size.nodes, size.springs, size.dim, size.mesh
    common = dict(n_nodes=nodes, n_springs=springs, dim=dim, dt=spec.dt, t_end=spec.t_end,
                  every=spec.output.every, outputs=spec.output.files(), method=method,
                  implicit=implicit, name=case.name)
    plan = _with_mesh(plan_scene(**common), mesh)
    if not measure or build is None:
        return plan
    if system is None:
        check_budget(plan, force=bool(case.run_options.get("force")), override=OVERRIDE)
        system, integrator, ctx = build()
    per_step = measure_step_seconds(system, integrator, spec.dt, ctx=ctx)
    return _with_mesh(plan_scene(**common, step_seconds=per_step), mesh)


def check_scene_fits(case, size) -> None:
    """The memory guard of a scene before its system is built (``force`` skips it): the model's
    peak from the file's numbers against the available memory."""
    if size is None or case.run_options.get("force"):
        return
    check_budget(plan_scene_case(case, size, measure=False), override=OVERRIDE)


def _implicit(integrator_spec) -> bool:
    """Whether the integrator is implicit (the integrator object alone is built, no system)."""
    return bool(integrator_spec.build().implicit)


def _with_mesh(plan: Plan, mesh: dict | None) -> Plan:
    """``plan`` with the mesh stages of a mesh system in front (generation, reading)."""
    if mesh is not None:
        stages = plan_mesh(**mesh).stages
        plan.stages[:0] = stages
        plan.assumptions.append("nodes ~ triangles / 2, springs ~ 3 triangles / 2 (the mesh's edges)")
    return plan
