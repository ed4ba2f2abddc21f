"""P2 elastic bodies: gradient and Hessian against finite differences of the energy, the
projected Hessian PSD, linear P2 elasticity equal to scikit-fem's, positive HRZ masses,
consistent P2 loads, stresses per quadrature point."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.mesh import Mesh
from femkit.solids import ElasticBody, body_forces, material, point_tangent, traction_forces

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helpers
from _meshes import assembled_fd_errors, mesh_by_dim, tet_box, tri_rect  # noqa: E402


def _body(d, name="stable_neo_hookean", **kw):
    X, cells = mesh_by_dim(d) if d == 3 else tri_rect(2, 1)
    return ElasticBody.from_mesh(Mesh(X, cells), material(name, mu=1.3, lam=2.1), "P2", **kw)


@pytest.mark.parametrize("name", ["linear", "stable_neo_hookean"])
@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_p2_gradient_and_hessian_match_finite_differences(name, d, rng):
    body = _body(d, name)
    assert body.rest.cells.shape[1] == (6 if d == 2 else 10) and body.rest.n_points == d + 1
    x = body.rest_positions + 0.08 * rng.standard_normal(body.rest_positions.shape)
    grad_err, hess_err = assembled_fd_errors(body, x)
    assert grad_err <= 1e-6 and hess_err <= 1e-6
    H = body.hessian(x)
    np.testing.assert_allclose(H.toarray(), H.toarray().T, atol=1e-12 * abs(H).max())


def test_p2_projected_hessian_is_psd_and_the_bound_holds(rng):
    body = _body(3)
    x = body.rest_positions + 0.15 * rng.standard_normal(body.rest_positions.shape)
    H = body.hessian(x).toarray()
    Hp = body.hessian(x, project=True).toarray()
    scale = np.abs(H).max()
    assert np.linalg.eigvalsh(H).min() < -1e-6 * scale        # the projection has work to do
    assert np.linalg.eigvalsh(Hp).min() >= -1e-10 * scale
    e = np.repeat(body.negative_bound(x), 3)
    assert np.linalg.eigvalsh(H + np.diag(e)).min() >= -1e-10 * scale


def test_p2_stresses_are_the_point_stresses_at_the_quadrature_points(rng):
    body = _body(3)
    mat = body.materials[0]
    x = body.rest_positions + 0.1 * rng.standard_normal(body.rest_positions.shape)
    P, F = body.stresses(x), body.deformation_gradients(x)
    assert P.shape == (4 * body.rest.n_cells, 3, 3) == F.shape
    for p in range(len(P)):
        np.testing.assert_allclose(P[p], point_tangent(mat, F[p])[1], atol=1e-12 * np.abs(P).max())
    # an affine motion: F is the same at every point, so are the per-cell fields
    A = np.array([[1.1, 0.2, 0.0], [0.0, 0.9, 0.1], [0.05, 0.0, 1.2]])
    f = body.element_fields(body.rest_positions @ A.T)
    np.testing.assert_allclose(f["J"], np.linalg.det(A), rtol=1e-12)


def _skfem_linear(d, lam, mu):
    import skfem
    from skfem.models.elasticity import linear_elasticity

    if d == 2:
        X, cells = tri_rect(3, 2, 2.0, 1.0)
        mesh, elem = skfem.MeshTri(X.T, cells.T), skfem.ElementTriP2()
    else:
        X, cells = tet_box(2, 1, 2, (1.0, 0.7, 1.3))
        mesh, elem = skfem.MeshTet(X.T, cells.T), skfem.ElementTetP2()
    basis = skfem.Basis(mesh, skfem.ElementVector(elem))
    return X, cells, basis, linear_elasticity(lam, mu).assemble(basis)


@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_linear_p2_stiffness_equals_scikit_fem(d):
    """The linear material's Hessian at rest is the small-strain stiffness: equal to scikit-fem's
    ``linear_elasticity`` on ``ElementVector(ElementTriP2 / ElementTetP2)`` on the same mesh, once
    its dofs are mapped to ours (by position and component)."""
    lam, mu = 2.1, 1.3
    X, cells, basis, K_ref = _skfem_linear(d, lam, mu)
    body = ElasticBody.from_mesh(Mesh(X, cells), material("linear", mu=mu, lam=lam), "P2")
    K = body.hessian(body.rest_positions).toarray()
    # scikit-fem's dof of (our node i, component c): match the nodal dofs by their positions
    pos = basis.doflocs.T                                    # (ndofs, d), components interleaved
    ours = np.repeat(body.rest_positions, d, axis=0)
    comp_ours = np.tile(np.arange(d), body.n)
    key = lambda P, c: [tuple(np.round(p, 9)) + (int(k),) for p, k in zip(P, c)]  # noqa: E731
    index = {k: i for i, k in enumerate(key(pos, np.tile(np.arange(d), len(pos) // d)))}
    perm = np.array([index[k] for k in key(ours, comp_ours)])
    assert sorted(perm) == list(range(K_ref.shape[0]))            # a permutation
    ref = K_ref.toarray()[np.ix_(perm, perm)]
    np.testing.assert_allclose(K, ref, atol=1e-10 * np.abs(ref).max(), rtol=0)
    assert np.abs(ref).max() > 0.5


def test_p2_lumped_masses_are_positive_and_hrz():
    body = ElasticBody.from_mesh(Mesh(*tet_box(2, 2, 1)), material("linear", mu=1.0, lam=1.0,
                                                                    density=3.0), "P2")
    m = body.lumped_masses()
    assert m.min() > 0 and m.sum() == pytest.approx(3.0 * body.rest.volumes.sum(), rel=1e-13)
    one = ElasticBody([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2, 3]],
                      material("linear", mu=1.0, lam=1.0), element="P2").lumped_masses()
    np.testing.assert_allclose(one * 6, [1 / 36] * 4 + [4 / 27] * 6, rtol=1e-13)


@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_p2_loads_are_the_consistent_ones(d):
    """A constant traction and body force on P2 nodes do the work of the exact integrals on
    every quadratic displacement: ``f . u(nodes) = int t . u`` for ``u = x^2`` (P1's equal
    shares would be off)."""
    X, cells = tri_rect(2, 2) if d == 2 else tet_box(2, 2, 2)
    mesh = Mesh(X, cells)
    body = ElasticBody.from_mesh(mesh, material("linear", mu=1.0, lam=1.0, density=2.0), "P2")
    from femkit.solids.quadratic import facet_nodes

    faces = np.concatenate([np.delete(cells, k, axis=1) for k in range(d + 1)])
    on = np.all(np.isclose(X[faces][:, :, 0], 1.0), axis=1)      # the face x = 1
    f = traction_forces(body.rest_positions, facet_nodes(mesh, faces[on]), np.eye(d)[1])
    y = body.rest_positions[:, 1]
    assert f[:, 1] @ y ** 2 == pytest.approx(1.0 / 3.0, rel=1e-12)    # int_0^1 y^2 (x = 1 face)
    b = body_forces(body, np.eye(d)[0] * 2.0)
    xx = body.rest_positions[:, 0]
    assert b[:, 0] @ xx ** 2 == pytest.approx(2.0 / 3.0, rel=1e-12)   # int x^2 over the unit box


@pytest.mark.parametrize("element", ["P1", "P2"])
def test_the_block_pattern_is_the_assembly_stacks_block_pattern(element):
    """The solids' node-slot pattern and femkit's one assembly pattern with block size ``d``
    (:meth:`SparsityPattern.from_cells`) are the same CSR structure, P1 and P2."""
    from femkit.fem.sparsity import SparsityPattern

    body = ElasticBody.from_mesh(Mesh(*tet_box(2, 1, 1)), material("linear", mu=1.0, lam=1.0),
                                 element)
    pat = body.pattern
    ref = SparsityPattern.from_cells(body.rest.cells, body.n, block=3)
    np.testing.assert_array_equal(pat.indptr, ref.indptr)
    np.testing.assert_array_equal(pat.indices, ref.indices)


def test_every_integrator_runs_a_p2_beam():
    """A bent P2 beam released: every integrator (projective dynamics, P1 only, refuses it in one
    line) follows RK4's motion of the tip, with HRZ masses; the clamp holds its edge nodes."""
    import warnings

    from femkit.dynamics.integrators import INTEGRATORS
    from femkit.dynamics.simulate import simulate
    from femkit.dynamics.system import elastic_system
    from femkit.errors import InputError
    from femkit.mesh.structured import structured_box

    mesh = structured_box(2, 1, 1, (2.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e3, nu=0.3), "P2")
    clamp = np.flatnonzero(body.rest_positions[:, 0] == 0.0)
    x0 = body.rest_positions.copy()
    x0[:, 2] -= 0.03 * x0[:, 0] ** 2
    system = elastic_system(body, x0=x0, pinned=clamp)
    dt = 0.1 / system.omega_max()                      # well below every explicit limit
    tip = np.flatnonzero(body.rest_positions[:, 0] == 2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = simulate(system, "rk4", dt / 2, 10 * dt).x[-1][tip, 2] - x0[tip, 2]
        assert np.all(ref > 0)
        for name in INTEGRATORS.names():
            if name == "projective":
                with pytest.raises(InputError, match="P1 bodies only"):
                    simulate(system, name, dt, 10 * dt)
                continue
            x = simulate(system, name, dt, 10 * dt).x[-1]
            np.testing.assert_array_equal(x[clamp], x0[clamp])
            rise = x[tip, 2] - x0[tip, 2]
            assert np.abs(rise - ref).max() <= 0.1 * np.abs(ref).max(), name
