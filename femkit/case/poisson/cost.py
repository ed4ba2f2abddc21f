"""The cost of a ``problem: poisson`` file before it runs: :func:`plan_poisson_case` (the kind's
``plan``: ``--dry-run``, budgets) and :func:`case_dimension` (the mesh's dimension as the plan
reads it).

The numbers come from ``case.spec``: a geometry's measure (:func:`femkit.case.cost.geometry_domain`)
or a ``.msh`` header's element count, priced by :func:`femkit.cost.plan_poisson`; tetrahedral runs
by the 3D memory laws (:func:`femkit.case.cost.with_3d_memory`).

``element: P2`` is priced before meshing as P1 on the mesh refined once more: P2 has a dof per
vertex and per edge, exactly the vertices of that refined mesh, and its stages after the mesh
work on as many unknowns; their memory is scaled by the ratio of the matrices' nonzeros
(:data:`P2_NONZERO_RATIO`, P2 on a mesh against P1 on the mesh refined once, measured on
femkit's meshes), the mesh stages are the refined mesh's (an upper bound).
"""

from __future__ import annotations

from ...cost import Plan, plan_poisson
from ..cost import TET_AS_TRIANGLES, geometry_domain, tets_per_h3, with_3d_memory

__all__ = ["plan_poisson_case", "case_dimension", "P2_NONZERO_RATIO"]

#: nnz(P2 stiffness on a mesh) / nnz(P1 stiffness on that mesh refined once), by dimension
#: (a unit-square mesh: 1.64; a structured Kuhn cube: 1.90).
P2_NONZERO_RATIO = {2: 1.64, 3: 1.90}


def case_dimension(case) -> int | None:
    """The dimension of a Poisson ``case``'s mesh before it is built, as the plan reads it (a
    geometry's entry, a ``.msh`` file's header); None when the input cannot be read (the mesh
    stage reports why)."""
    from ...cost import msh_has_volume
    from ...errors import FemkitError

    mesh = case.spec.mesh
    try:
        if mesh.file is not None:
            return 3 if msh_has_volume(mesh.file) else 2
        return geometry_domain(mesh.geometry, dict(mesh.params))[0]
    except (FemkitError, OSError):
        return None


def plan_poisson_case(case, *, measure: bool = True) -> Plan:
    """The plan of a Poisson case (from ``case.spec``); with ``measure`` its seconds are scaled
    by this machine's speed now (:func:`femkit.cost.machine_speed`, ~0.25 s of probing)."""
    from ...cost import machine_speed, msh_has_volume, msh_triangle_count

    spec = case.spec
    mesh, out = spec.mesh, spec.output
    outputs = tuple(k for k, on in (("vtu", out.vtu), ("xdmf", out.xdmf), ("png", out.plot)) if on)
    p2 = spec.element != "P1"
    common = dict(refine=mesh.refine + (1 if p2 else 0), method=case.solver.method,
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
    if p2:
        _price_element(plan, spec.element, case_dimension(case) or 2)
    if spec.adaptive:
        plan.assumptions.append("adaptive refinement: only the first level is costed; the "
                                "adaptive budgets (max_dofs, max_time, max_levels) bound the rest")
    return plan


def _price_element(plan: Plan, element: str, dim: int) -> None:
    """Turn the plan of P1 on the mesh refined once more into the plan of ``element`` (P2) on the
    case's mesh (module docstring): the stages after the mesh priced for P2's denser matrix."""
    factor = P2_NONZERO_RATIO[dim]
    for st in plan.stages:
        if st.name not in ("mesh", "refine"):
            st.peak_bytes *= factor
    if "nonzeros" in plan.sizes:
        plan.sizes["nonzeros"] = plan.sizes["nonzeros"] * factor
    plan.title = f"{plan.title}, element {element}"
    plan.assumptions.insert(0, f"element {element}: priced as P1 on the mesh refined once more (the "
                            f"same unknowns: a dof per vertex and per edge), memory after the mesh "
                            f"x{factor:g} for {element}'s denser rows")


def _tetrahedral_plan(tets: float, source: str, title: str, common: dict, *,
                     generated: bool) -> Plan:
    """The plan of a tetrahedral Poisson run of ``tets`` cells before refinement (``generated``
    by gmsh, else read from a file): memory by the 3D laws (:mod:`femkit.cost.tetrahedra`, as
    :func:`check_mesh_fits` with ``dim=3``), time and the stages without a 3D law as
    :data:`TET_AS_TRIANGLES` triangles of the 2D model per tetrahedron; 8 children per
    refinement (Bey 1995); sizes and the stages' words in tetrahedra."""
    import re

    k = common["refine"]
    plan = with_3d_memory(plan_poisson(triangles=TET_AS_TRIANGLES * tets * 2.0 ** k, **common), tets, k,
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
