"""The cost of a solid case before it runs (``KINDS["solid"].plan``, ``--dry-run``, budgets).

Element counts come from the geometry's measure (:data:`femkit.mesh.GEOMETRIES`: volume and
surface area in 3D, area and line length in 2D) and ``h``; a mesh file is counted from its header
(:func:`femkit.cost.msh_triangle_count` counts the highest-dimensional cells). A mesh the formula
puts below :data:`COUNT_BELOW` cells is generated and counted instead (well under a second; gmsh
also caps its element size at about a tenth of the domain's diagonal, which no measure shows, so
a coarse ``h`` gives more cells than any formula of it). The constants are stated in the plan's
assumptions: gmsh's tetrahedra number about ``4.13 V / h^3 + 1.44 A / h^2`` (fitted on the
``beam`` and ``unit_cube`` geometries at h 0.08-0.25: within 10 %), its triangles
``2.3 A / h^2``; P1 rows hold
about 15 nodes in 3D and 7 in 2D; a sparse direct factor of a 3D stiffness matrix fills in
about ``n^(1/3)`` times its nonzeros (nested dissection), 2D ``log n``; the compiled element pass
runs at least 5e4 elements/s (gradient + projected Hessian, docs/benchmarks.md). P2 (``element:
P2``) adds a node per edge, about ``points + cells`` of them (Euler's formula: exact in 2D,
within 10 % on gmsh's tetrahedra), rows of about 12 (2D) and 27 (3D) nodes, and a cell costs
the pass up to :data:`P2_PASS_COST` P1 cells (its points' SVDs and a 12 x 12 or 30 x 30
Hessian: measured 2.5e5 triangles/s and 2.1e4 tetrahedra/s, against 3e6 and 3.3e5 for P1).

:func:`check_solid_fits` is the memory guard the runner calls before gmsh starts (the role
:func:`femkit.case.cost.check_mesh_fits` has for the other kinds, in tetrahedra as well).
"""

from __future__ import annotations

import functools
import math

from ..contact import obstacle_facets
from ...cost import Plan, Stage, check_budget, contact_stage, load_constants
from ...cost.plan import round_down, round_up
from ..cost import OVERRIDE, geometry_domain

__all__ = ["plan_solid_case", "solid_sizes", "check_solid_fits", "check_explicit_step"]

#: cells per h^dim of measure, and per h^(dim-1) of boundary measure (3D: gmsh's surface layer)
CELLS_PER_MEASURE = {2: 2.3, 3: 4.13}
CELLS_PER_BOUNDARY = {2: 0.0, 3: 1.44}

#: a generated mesh predicted smaller than this is generated and counted by the plan
COUNT_BELOW = 5000
ROW_NODES = {2: 7.0, 3: 15.0}
P2_ROW_NODES = {2: 12.0, 3: 27.0}
#: what one P2 cell costs the element pass, in P1 cells
P2_PASS_COST = {2: 12.0, 3: 16.0}
ELEMENTS_PER_SECOND = 5e4
REST_BYTES_PER_CELL = 400.0     # rest data, element fields and the pass's work arrays (P2: 5x,
                                # gradients at every quadrature point and 36 or 100 node slots)


def solid_sizes(mesh: dict) -> tuple[int, float, float]:
    """``(dim, cells, points)`` predicted for a solid's ``mesh:`` mapping (counted exactly for
    a generated mesh the formula puts below :data:`COUNT_BELOW` cells)."""
    if "file" in mesh:
        from ...cost import msh_triangle_count

        cells, _ = msh_triangle_count(mesh["file"])
        dim = 3  # a .msh counted by its header: assume the worse (3D) node ratio
        return dim, float(cells), float(cells) / 4.5
    dim, size, boundary = geometry_domain(mesh["geometry"], mesh.get("params"))
    h = float(mesh["h"])
    cells = CELLS_PER_MEASURE[dim] * size / h ** dim \
        + CELLS_PER_BOUNDARY[dim] * boundary / h ** (dim - 1)
    if cells < COUNT_BELOW:
        params = tuple(sorted(dict(mesh.get("params") or {}).items()))
        return (dim, *_counted(mesh["geometry"], h, params))
    points = cells / (4.5 if dim == 3 else 2.0) + 0.5 * boundary / h ** (dim - 1)
    return dim, cells, points


@functools.lru_cache(maxsize=32)
def _counted(geometry: str, h: float, params: tuple) -> tuple[float, float]:
    """``(cells, points)`` of the generated mesh (a small one: the plan's exact count)."""
    from ...mesh import generate

    mesh = generate(geometry, h, **dict(params))
    return float(mesh.n_cells), float(len(mesh.points))


def plan_solid_case(case, *, measure: bool = True) -> Plan:
    """The plan of a solid case: mesh, the Newton solves (static load steps or time steps) and
    the frames written. ``measure`` is accepted for the kind interface; the model is not
    calibrated by a timed run (its seconds are an order of magnitude)."""
    spec = case.spec
    dim, cells, points = solid_sizes(spec.mesh)
    p2 = spec.element == "P2"
    if p2:
        points = points + (points + cells)            # a node per edge
    if spec.bodies is not None:     # bodies of the file's mesh size each
        cells, points = cells * len(spec.bodies), points * len(spec.bodies)
    dofs = dim * points
    nnz = dim * dim * (P2_ROW_NODES if p2 else ROW_NODES)[dim] * points
    fill = max(1.0, dofs ** (1.0 / 3.0)) if dim == 3 else max(1.0, math.log(max(dofs, 2.0)))
    factor_bytes = 12.0 * nnz * fill
    steps = spec.steps
    per_step, what_iterates = _iterations_per_step(spec)
    iterations = steps * per_step
    frames = steps // spec.output.every + 1
    pass_s = cells * (P2_PASS_COST[dim] if p2 else 1.0) / ELEMENTS_PER_SECOND
    # Newton factors the tangent each iteration; projective dynamics solves with a kept factor
    factor_s = nnz * fill * (2e-8 if what_iterates == "Newton" else 4e-9)
    frame_bytes = 8.0 * (6 * points + (dim + 1) * cells + (dim + 3) * cells)
    out = spec.output
    out_bytes = (frames * frame_bytes if out.vtu else 0.0) + (2e5 if out.png else 0.0) \
        + (frames * 1e5 if out.gif else 0.0)
    what = "triangles" if dim == 2 else "tetrahedra"
    counted = "file" not in spec.mesh and cells < COUNT_BELOW
    stages = [
        Stage("mesh", cells * 2e-5, cells * (8.0 * (dim + 1) + 64.0), 0.0,
              f"{what} {'' if counted else '~'}{cells:,.0f}"),
        Stage("solve", iterations * (pass_s + factor_s),
              cells * REST_BYTES_PER_CELL * (5.0 if p2 else 1.0) + 3 * 12.0 * nnz + factor_bytes
              + frames * 16.0 * dofs, 0.0,
              f"{iterations:,} {what_iterates} iterations ({'up to ' if what_iterates != 'Newton' else '~'}"
              f"{per_step:,} per {'load' if spec.static else 'time'} step)"),
        Stage("output", frames * frame_bytes / 2e7, frame_bytes * 4, out_bytes,
              f"{frames} frames"),
    ]
    if spec.contact is not None:   # boundary triangles ~ 12 n^(2/3) of n nodes (segments 4 sqrt n)
        surface = 12.0 * points ** (2.0 / 3.0) if dim == 3 else 4.0 * points ** 0.5
        stages.append(contact_stage(steps, surface + obstacle_facets(spec.contact),
                                    pass_s + factor_s, per_step))
    title = (f"{case.name}: {spec.mesh.get('geometry', spec.mesh.get('file'))} "
             f"{'static' if spec.static else spec.integrator.method}")
    sizes = {what: cells, "points": points, "unknowns": dofs, "nonzeros": nnz,
             "steps": steps, "frames": frames}

    def suggest(kind: str, limit: float) -> str:
        """A time integration too long for a budget: the step and end time that fit."""
        if spec.static is not None or kind not in ("time", "steps"):
            return ""
        k = limit / max(plan.seconds if kind == "time" else steps, 1e-300)
        fewer = f"integrator.options.iterations <= {max(1, int(per_step * k)):,} or " \
            if kind == "time" and what_iterates != "Newton" else ""
        return f"{fewer}dt >= {round_up(spec.dt / k)} or t_end <= {round_down(spec.t_end * k)}"

    plan = Plan("solid", title, sizes, stages, load_constants()["bytes"]["baseline"],
                assumptions=[
                    f"{cells:,.0f} {what}: the mesh generated and counted" if counted else
                    f"{CELLS_PER_MEASURE[dim]} x measure / h^{dim} + {CELLS_PER_BOUNDARY[dim]} x "
                    f"boundary / h^{dim - 1} {what} (gmsh)" if "file" not in spec.mesh else
                    f"{cells:,.0f} {what} in {spec.mesh['file']} (its header)",
                    f"direct factor fill {fill:.0f}x the matrix nonzeros",
                    f"element pass >= {ELEMENTS_PER_SECOND:.0e} elements/s; seconds are an "
                    "order of magnitude (not calibrated on this machine)"])
    plan.suggest = suggest
    return plan


def _iterations_per_step(spec) -> tuple[int, str]:
    """``(iterations, what)`` per load or time step: Newton's (~4 static, ~3 dynamic) or the
    integrator's own bound (``iterations`` of projective dynamics: every one is a local pass and
    a solve, so a billion of them is priced as such)."""
    if spec.static is not None:
        return 4, "Newton"
    bound = getattr(spec.integrator.build(), "iterations", None)
    if isinstance(bound, int) and spec.integrator.method != "newton":
        return max(1, bound), f"{spec.integrator.method} local/global"
    return 3, "Newton"


def check_solid_fits(case) -> None:
    """Refuse, before meshing, a solid run whose predicted memory exceeds the available memory
    (:class:`~femkit.errors.BudgetExceededError`, one line); ``--force`` skips it."""
    if case.options.force:
        return
    check_budget(plan_solid_case(case, measure=False), case.options.limits,
                 override=OVERRIDE)


def check_explicit_step(case, system) -> None:
    """Refuse an explicit integration whose step exceeds its critical step on the built mesh:
    ``dt > bound / omega_max`` (``omega_max`` of ``M^-1 K`` at the start by power iteration,
    :func:`femkit.dynamics.stability.estimate_omega_max`, which approaches it from below, so a
    refused step is surely unstable). Such a run only blows up: one line
    (:class:`~femkit.errors.BudgetExceededError`, exit 2) before anything is written, naming
    the critical step; ``--force`` runs it anyway."""
    from ...dynamics.stability import critical_dt, estimate_omega_max
    from ...errors import BudgetExceededError

    spec = case.spec
    integrator = spec.integrator.build()
    if case.options.force or integrator.implicit:
        return
    omega = float(estimate_omega_max(system, system.x0))
    dt_crit = float(critical_dt(omega, integrator.stability_bound))
    if spec.dt > dt_crit:
        raise BudgetExceededError(
            f"dt: {spec.dt:g} exceeds the critical step {dt_crit:.4g} of the explicit "
            f"{integrator.name} on this mesh ({integrator.stability_bound:.4g} / omega_max, "
            f"omega_max = {omega:.4g}): the run would blow up; use dt <= "
            f"{round_down(dt_crit)} or an implicit integrator (newton, variational_symplectic) "
            f"(or {OVERRIDE} to run anyway)", "dt", spec.dt, dt_crit)
