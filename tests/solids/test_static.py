"""Quasi-static equilibrium: patch test, rollers against the analytic uniaxial state, a
cantilever against scikit-fem's linear elasticity, and Newton's failure record."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import EquilibriumError, InputError
from femkit.solids import MATERIALS, ElasticBody
from femkit.solids.boundary import Dirichlet, traction_forces
from femkit.solids.static import solve_static

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helpers
from _meshes import facets_on, nodes_on, tet_box, tri_rect  # noqa: E402

NAMES = ["linear", "corotational", "stvk", "stable_neo_hookean"]


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_patch_test_affine_boundary_motion_is_reproduced_inside(name, d, rng):
    X, cells = tri_rect(4, 4, diagonal="uniform") if d == 2 else tet_box(3, 3, 3)
    boundary = np.flatnonzero(np.any((X <= 1e-12) | (X >= 1 - 1e-12), axis=1))
    interior = np.setdiff1d(np.arange(len(X)), boundary)
    A = 0.12 * rng.standard_normal((d, d))
    b = 0.05 * rng.standard_normal(d)
    body = ElasticBody(X, cells, MATERIALS.get(name)(1.0, 2.0))
    bc = Dirichlet(body.n, d).fix(boundary, displacement=lambda P: P @ A.T + b, rest_positions=X)
    res = solve_static(body, bc)
    assert res.converged and len(interior) > 0
    assert np.abs(res.u[interior] - (X[interior] @ A.T + b)).max() <= 1e-10 * np.abs(A).max()


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_rollers_give_the_uniaxial_stress_state(nu):
    """Rollers on x=0, y=0, z=0 (one component each), x=1 pulled by 1e-6: the homogeneous
    uniaxial state eps_yy = eps_zz = -nu eps_xx of linear elasticity, everywhere."""
    X, cells = tet_box(2, 2, 2)
    body = ElasticBody(X, cells, MATERIALS.get("linear").from_young(1.0, nu))
    bc = Dirichlet(body.n, 3)
    for axis in range(3):
        bc.fix(nodes_on(X, axis, 0.0), components=[axis])
    eps = 1e-6
    bc.fix(nodes_on(X, 0, 1.0), components=[0], displacement=eps)
    res = solve_static(body, bc)
    expected = X * np.array([eps, -nu * eps, -nu * eps])
    assert np.abs(res.u - expected).max() <= 1e-10 * eps
    # output fields: stretches 1 + eps, 1 - nu eps (twice); von Mises of uniaxial stress = E eps
    fields = body.element_fields(res.x)
    np.testing.assert_allclose(fields["principal_stretches"],
                               np.tile(sorted([1 + eps, 1 - nu * eps, 1 - nu * eps], reverse=True),
                                       (len(cells), 1)), atol=1e-12)
    np.testing.assert_allclose(fields["von_mises"], 1.0 * eps, rtol=1e-5)


def _skfem_cantilever(X, cells, mu, lam, q, length):
    from skfem import (Basis, ElementTetP1, ElementVector, FacetBasis, LinearForm, MeshTet, asm,
                       condense, solve)
    from skfem.models.elasticity import linear_elasticity

    mesh = MeshTet(X.T.copy(), cells.T.copy())
    e = ElementVector(ElementTetP1())
    basis = Basis(mesh, e)
    K = asm(linear_elasticity(lam, mu), basis)
    tip = FacetBasis(mesh, e, facets=mesh.facets_satisfying(lambda x: np.isclose(x[0], length)))

    @LinearForm
    def traction(v, w):
        return -q * v[2]

    f = asm(traction, tip)
    clamped = basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    u = solve(*condense(K, f, D=clamped))
    return u[basis.nodal_dofs].T           # (n, 3)


@pytest.mark.parametrize("name", NAMES)
def test_cantilever_small_load_matches_scikit_fem(name):
    length = 4.0
    X, cells = tet_box(8, 2, 2, (length, 1.0, 1.0))
    mat = MATERIALS.get(name).from_young(1000.0, 0.3)
    q = 1e-5                                             # tip deflection ~1e-6 of the length
    body = ElasticBody(X, cells, mat)
    bc = Dirichlet(body.n, 3).fix(nodes_on(X, 0, 0.0))
    f = traction_forces(X, facets_on(X, cells, 0, length), [0.0, 0.0, -q])
    res = solve_static(body, bc, f)
    ref = _skfem_cantilever(X, cells, mat.mu, mat.lam, q, length)
    tip = nodes_on(X, 0, length)
    w, w_ref = res.u[tip, 2].mean(), ref[tip, 2].mean()
    assert w_ref < 0
    assert abs(w - w_ref) <= 1e-4 * abs(w_ref)
    assert np.abs(res.u - ref).max() <= 1e-4 * np.abs(ref).max()


def test_load_steps_and_record():
    X, cells = tet_box(4, 1, 1, (4.0, 1.0, 1.0))
    body = ElasticBody(X, cells, MATERIALS.get("stable_neo_hookean").from_young(100.0, 0.3))
    bc = Dirichlet(body.n, 3).fix(nodes_on(X, 0, 0.0))
    f = traction_forces(X, facets_on(X, cells, 0, 4.0), [0.0, 0.0, -2.0])
    res = solve_static(body, bc, f, load_steps=3, rtol=1e-12)
    assert [s.load_factor for s in res.steps] == pytest.approx([1 / 3, 2 / 3, 1.0])
    assert res.converged and res.iterations == sum(s.iterations for s in res.steps)
    for s in res.steps:       # Newton converges: the last residual is tiny next to the first
        assert s.residuals[-1] <= 1e-11 * s.residuals[0]
    # the exact Hessian where it gives descent: the same equilibrium, quadratic convergence
    auto = solve_static(body, bc, f, load_steps=3, project="auto", rtol=1e-12)
    assert np.abs(auto.x - res.x).max() <= 1e-10 * np.abs(res.u).max()
    assert 2 * auto.iterations <= res.iterations       # measured: 15 against 62
    with pytest.raises(EquilibriumError) as info:
        solve_static(body, bc, f, load_steps=2, max_iterations=2)
    err = info.value
    assert err.load_step == 1 and len(err.record.steps[0].residuals) == 3
    assert np.allclose(err.x, X)              # the last equilibrium: the rest state
    assert "residual" in str(err)


def test_bad_static_input():
    X, cells = tet_box(1, 1, 1)
    body = ElasticBody(X, cells, MATERIALS.get("stvk")(1.0, 1.0))
    with pytest.raises(InputError, match="rigid-body"):
        solve_static(body, Dirichlet(body.n, 3))
    with pytest.raises(InputError, match="prescribed twice"):
        Dirichlet(body.n, 3).fix([0], displacement=0.0).fix([0], [1], displacement=1.0)
    with pytest.raises(InputError, match="components"):
        Dirichlet(body.n, 3).fix([0], components=[3])
