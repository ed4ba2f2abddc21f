"""What the cost of every kind of case file shares: geometry measures, the mesh memory guard, a
scene's measured step, the 3D memory laws applied to a plan.

The cost model (:mod:`femkit.cost`) takes numbers; each problem kind turns its file into them in
its own package (``femkit/case/<kind>/cost.py``: :func:`femkit.case.poisson.cost.plan_poisson_case`,
:func:`femkit.case.scene.cost.plan_scene_case`, :func:`femkit.case.solid.cost.plan_solid_case`,
registered as ``KINDS[...].plan``); this module holds what they share, so no library layer plans
anything:

* :func:`geometry_domain` reads a geometry's area and line length from its entry in
  :data:`femkit.mesh.GEOMETRIES` (one registration declares a geometry and its measure);
* :func:`check_mesh_fits` is the memory guard the runners call before generating or refining a
  mesh (:func:`femkit.mesh.generate`, :func:`femkit.mesh.refine` do not check themselves): a
  mesh whose predicted memory exceeds the available memory is refused before gmsh or numpy
  start (:class:`~femkit.errors.BudgetExceededError`, one line with the ``h`` that fits);
* :func:`measure_step_seconds` times a scene's first batch of steps (what ``plan_scene`` is
  given as ``step_seconds``);
* :func:`with_3d_memory` prices a plan's stages by the tetrahedral memory laws.

:mod:`femkit.case.budget` checks a case's plan against its limits before it runs. Nothing here
imports another module of ``femkit.case``: the runners import this module (the guard), so it
stays below them.
"""

from __future__ import annotations

import math
import time

from ..cost import Plan, check_budget, plan_mesh

__all__ = ["geometry_domain", "check_mesh_fits", "measure_step_seconds", "with_3d_memory",
           "tets_per_h3", "TETS_PER_H3", "TET_AS_TRIANGLES", "OVERRIDE"]

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


def with_3d_memory(plan: Plan, tets: float, refine: int, method: str) -> Plan:
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
        plan = with_3d_memory(plan_mesh(triangles=TET_AS_TRIANGLES * triangles * 2.0 ** refine,
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
