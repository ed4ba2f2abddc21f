"""Geometric multigrid (preconditioner ``gmg``, method ``fmg``) on refinement hierarchies.

Acceptance numbers of the issue: V(2,2)-cycle energy-norm contraction <= 0.15, growing by < 0.05
from 3 to 7 levels; FMG L2 error within 1.2x of the exact discrete solution's on every one of 5
levels; gmg-PCG to rtol 1e-8 on contrast 1e6 and aspect ratio 100; the V-cycle is SPD.
Coarse meshes have h = 0.5; 7 levels (6 refinements) stay below ~82k unknowns.
"""

from __future__ import annotations


import numpy as np
import pytest

from femkit.errors import HierarchyError, InputError
from femkit.fem import (apply_dirichlet, assemble_load, assemble_stiffness, dirichlet_values,
                        error_norms)
from femkit.mesh import Mesh, MeshHierarchy, boundary_nodes, generate
from femkit.solvers import get_preconditioner, pcg, solve
from femkit.solvers.gmg import Multigrid

GEOMETRIES = ["unit_square", "l_shape", "annulus"]

#: Largest growth of the V(2,2) factor from 3 to 7 levels (the issue's acceptance number); measured
#: with the default omega = 1.25: unit square 0.047, L-shape 0.040, annulus 0.003 (docs/methods.md).
GROWTH_LIMIT = {"unit_square": 0.05, "l_shape": 0.05, "annulus": 0.05}


def dirichlet_system(mesh, f=1.0, kappa=1.0, g=0.0):
    K = assemble_stiffness(mesh, kappa)
    F = assemble_load(mesh, f, rule="gauss3")
    nodes = boundary_nodes(mesh)
    vals = dirichlet_values(mesh, nodes, g) if callable(g) else g
    return apply_dirichlet(K, F, nodes, vals)


@pytest.fixture(scope="module")
def coarse_meshes():
    return {g: generate(g, 0.5) for g in GEOMETRIES}


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_vcycle_factor_is_small_and_level_independent(geometry, coarse_meshes):
    rho = {}
    for levels in (3, 7):   # refinements: 4 and 8 meshes
        H = MeshHierarchy.from_refinement(coarse_meshes[geometry], levels - 1)
        sys = dirichlet_system(H.finest)
        rho[levels] = Multigrid(sys.A, H, free=sys.free, sweeps=2).contraction(30)
    print(f"{geometry}: V(2,2) factor {rho[3]:.3f} (3 levels), {rho[7]:.3f} (7 levels)")
    assert rho[3] <= 0.15 and rho[7] <= 0.15
    assert rho[7] - rho[3] < GROWTH_LIMIT[geometry]


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_vcycle_is_symmetric_positive_definite(geometry, coarse_meshes):
    H = MeshHierarchy.from_refinement(coarse_meshes[geometry], 3)
    sys = dirichlet_system(H.finest)
    M = get_preconditioner("gmg")(sys.A, hierarchy=H, free=sys.free)
    rng = np.random.default_rng(3)
    for _ in range(5):
        x, y = rng.standard_normal((2, sys.A.shape[0]))
        xMy, yMx = x @ M(y), y @ M(x)
        assert abs(xMy - yMx) <= 1e-12 * (abs(xMy) + np.linalg.norm(x) * np.linalg.norm(M(x)))
        assert x @ M(x) > 0


def test_fmg_reaches_the_discretisation_error_on_every_level():
    pi = np.pi
    u = lambda x, y: np.sin(pi * x) * np.sin(pi * y)          # noqa: E731
    f = lambda x, y: 2 * pi * pi * np.sin(pi * x) * np.sin(pi * y)  # noqa: E731
    H = MeshHierarchy.from_refinement(generate("unit_square", 0.5), 5)
    for lvl in range(1, H.n_levels):
        sub = MeshHierarchy(H.meshes[:lvl + 1], H.prolongations[:lvl], H.injections[:lvl])
        mesh = sub.finest
        sys = dirichlet_system(mesh, f=f)
        res = solve(sys.A, sys.b, method="fmg", hierarchy=sub, free=sys.free)
        exact = solve(sys.A, sys.b, method="direct").x
        e_fmg = error_norms(mesh, sys.expand(res.x), u)["L2"]
        e_disc = error_norms(mesh, sys.expand(exact), u)["L2"]
        assert res.converged and res.method == "fmg"
        assert e_fmg <= 1.2 * e_disc, (lvl, e_fmg / e_disc)
        assert res.iterations <= 3
        assert res.info["algebraic_error_estimate"] <= 0.1 * res.info["discretisation_error_estimate"]


def test_fmg_with_level_systems_handles_inhomogeneous_dirichlet_data():
    u = lambda x, y: np.exp(x) * np.sin(y) + x * y     # harmonic  # noqa: E731
    H = MeshHierarchy.from_refinement(generate("l_shape", 0.5), 4)
    systems = [dirichlet_system(m, f=0.0, g=u) for m in H.meshes]
    sys = systems[-1]
    res = solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, levels=systems[:-1])
    exact = solve(sys.A, sys.b, method="direct").x
    e_fmg = error_norms(H.finest, sys.expand(res.x), u)["L2"]
    e_disc = error_norms(H.finest, sys.expand(exact), u)["L2"]
    assert res.converged and res.info["stopped_by"] == "discretisation-error estimate"
    assert e_fmg <= 1.2 * e_disc
    # restricted right-hand sides carry the lifting's boundary layer: the estimate grows with
    # refinement, FMG notices and certifies by the residual rule instead
    res2 = solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, rtol=1e-8)
    assert res2.info["estimate_credible"] is False
    assert res2.converged and res2.info["stopped_by"] == "residual rule"
    assert res2.true_residual <= 1e-8 * np.linalg.norm(sys.b)


def test_fmg_target_residual_meets_the_residual_rule():
    H = MeshHierarchy.from_refinement(generate("annulus", 0.5), 4)
    sys = dirichlet_system(H.finest)
    res = solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, target="residual",
                rtol=1e-10)
    assert res.converged and res.true_residual <= 1e-10 * res.rhs_norm
    assert res.setup_time > 0 and res.solve_time > 0
    assert len(res.residuals) == res.iterations + 1


def test_high_contrast_checkerboard_converges_with_gmg_pcg():
    H = MeshHierarchy.from_refinement(generate("checkerboard", 0.25), 4)
    m = H.finest
    kappa = np.where(m.cell_tags == m.tag_names["high"], 1e6, 1.0)
    sys = dirichlet_system(m, kappa=kappa)
    res = solve(sys.A, sys.b, method="pcg", preconditioner="gmg", rtol=1e-8,
                preconditioner_options={"hierarchy": H, "free": sys.free})
    print(f"checkerboard 1e6, n = {sys.A.shape[0]}: gmg-PCG {res.iterations} iterations")
    assert res.converged and res.iterations <= 15


def test_aspect_ratio_100_converges_with_gmg_pcg():
    c = generate("unit_square", 0.5)
    stretched = Mesh(points=c.points * [100.0, 1.0], triangles=c.triangles,
                     boundary_edges=c.boundary_edges, boundary_tags=c.boundary_tags,
                     tag_names=c.tag_names)
    H = MeshHierarchy.from_refinement(stretched, 4)
    sys = dirichlet_system(H.finest)
    res = solve(sys.A, sys.b, method="pcg", preconditioner="gmg", rtol=1e-8,
                preconditioner_options={"hierarchy": H, "free": sys.free})
    print(f"aspect ratio 100, n = {sys.A.shape[0]}: gmg-PCG {res.iterations} iterations")
    assert res.converged and res.iterations <= 60


def test_rediscretised_coarse_operators_equal_galerkin_for_constant_kappa():
    H = MeshHierarchy.from_refinement(generate("l_shape", 0.5), 3)
    systems = [dirichlet_system(m) for m in H.meshes]
    sys = systems[-1]
    gal = Multigrid(sys.A, H, free=sys.free)
    red = Multigrid(sys.A, H, free=sys.free, coarse_operators=[s.A for s in systems[:-1]])
    r = np.random.default_rng(0).standard_normal(sys.A.shape[0])
    np.testing.assert_allclose(gal.vcycle(r), red.vcycle(r), rtol=1e-9, atol=1e-12)
    assert gal.info["coarse"] == "galerkin" and red.info["coarse"] == "given"


@pytest.mark.parametrize("call", [
    pytest.param(lambda A, b: solve(A, b, method="pcg", preconditioner="gmg"), id="gmg"),
    pytest.param(lambda A, b: solve(A, b, method="fmg"), id="fmg")])
def test_missing_hierarchy_is_one_line_error_naming_amg_rs(call):
    m = generate("unit_square", 0.5)
    sys = dirichlet_system(m)
    with pytest.raises(HierarchyError, match="amg_rs") as exc:
        call(sys.A, sys.b)
    assert "\n" not in str(exc.value)
    assert isinstance(exc.value, InputError)


def test_mismatched_system_and_bad_options_are_input_errors():
    H = MeshHierarchy.from_refinement(generate("unit_square", 0.5), 2)
    sys = dirichlet_system(H.finest)
    with pytest.raises(HierarchyError, match="free nodes"):
        get_preconditioner("gmg")(sys.A, hierarchy=H)          # free= missing
    with pytest.raises(HierarchyError, match="MeshHierarchy"):
        get_preconditioner("gmg")(sys.A, hierarchy="levels", free=sys.free)
    with pytest.raises(InputError, match="sweeps"):
        get_preconditioner("gmg")(sys.A, hierarchy=H, free=sys.free, sweeps=0)
    with pytest.raises(InputError, match="omega"):
        get_preconditioner("gmg")(sys.A, hierarchy=H, free=sys.free, omega=2.5)
    with pytest.raises(InputError, match="fraction"):
        solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, fraction=0)
    with pytest.raises(InputError, match="target"):
        solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, target="exact")
    with pytest.raises(InputError, match="levels"):
        solve(sys.A, sys.b, method="fmg", hierarchy=H, free=sys.free, levels=[])


def test_gmg_pcg_iterations_are_flat_and_setup_is_reported():
    its = []
    for k in (3, 5):
        H = MeshHierarchy.from_refinement(generate("unit_square", 0.5), k)
        sys = dirichlet_system(H.finest)
        M = get_preconditioner("gmg")(sys.A, hierarchy=H, free=sys.free)
        res = pcg(sys.A, sys.b, M=M, rtol=1e-8)
        assert res.converged
        its.append(res.iterations)
        assert M.info["levels"] == k + 1 and M.info["operator_complexity"] < 1.5
    assert its[1] <= its[0] + 1 and its[1] <= 8
