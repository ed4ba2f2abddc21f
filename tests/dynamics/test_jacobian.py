"""Spring Jacobian: analytic K vs central differences, symmetry, definiteness fixes, matrix-free product."""

import numpy as np
import pytest

from femkit.dynamics.forces import GroundContact, Gravity, SphereContact
from femkit.dynamics.forces.jacobian import spring_blocks
from femkit.dynamics.system import MassSpringSystem
from femkit.errors import UnknownNameError


def random_system(dim, draw, *, contacts=True, compress=False, damping=0.0):
    """Random springs among 9 particles; rest lengths random (so many springs are compressed)."""
    rng = np.random.default_rng(draw)
    n = 9
    x0 = rng.random((n, dim))
    a, b = np.triu_indices(n, 1)
    keep = rng.random(len(a)) < 0.5
    springs = np.stack([a[keep], b[keep]], axis=1)
    _, l0 = None, np.linalg.norm(x0[springs[:, 1]] - x0[springs[:, 0]], axis=1)
    rest = l0 * (rng.uniform(1.3, 2.0, len(l0)) if compress else rng.uniform(0.5, 1.5, len(l0)))
    forces = [Gravity(9.81)]
    if contacts:
        forces += [GroundContact(80.0, height=0.4), SphereContact(np.full(dim, 0.6), 0.35, 60.0)]
    s = MassSpringSystem(x0, rng.uniform(0.5, 2.0, n), springs, rng.uniform(1.0, 5.0, len(springs)), rest=rest,
                         damping=damping, pinned=[0], forces=forces)
    return s, rng


def fd_jacobian(fun, z, h=1e-6):
    z = z.ravel()
    cols = []
    for c in range(z.size):
        e = np.zeros_like(z)
        e[c] = h
        cols.append((fun(z + e) - fun(z - e)) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
@pytest.mark.parametrize("draw", [1, 2, 3], ids=lambda s: f"draw{s}")
def test_stiffness_matches_central_differences(dim, draw):
    s, rng = random_system(dim, draw)
    x = s.x0 + 0.02 * rng.standard_normal(s.x0.shape)
    v = rng.standard_normal(s.x0.shape)
    K = s.stiffness_matrix(x).toarray()
    J = fd_jacobian(lambda z: s.force(z.reshape(x.shape), v).ravel(), x)
    free = s.free_dofs
    assert np.abs(K[free] + J[free]).max() <= 1e-6 * np.abs(K).max()
    # and contacts really are active in this configuration (otherwise the test proves less)
    assert s.energies(x, v)["contact"] > 0


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_damping_matrix_matches_central_differences_in_v(dim):
    from femkit.dynamics.forces import ViscousDamping

    rng = np.random.default_rng(7)
    x0 = rng.random((6, dim))
    springs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [0, 5], [1, 4]])
    s = MassSpringSystem(x0, 1.0, springs, 3.0, damping=rng.uniform(0.1, 1.0, len(springs)),
                         forces=[ViscousDamping(0.2)])
    v = rng.standard_normal(x0.shape)
    D = s.damping_matrix(x0).toarray()
    J = fd_jacobian(lambda z: s.force(x0, z.reshape(v.shape)).ravel(), v)
    assert np.allclose(D, -J, rtol=0, atol=1e-7 * np.abs(D).max())
    assert np.allclose(D, D.T)


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
@pytest.mark.parametrize("fix", [None, "clamp", "regularize"], ids=["nofix", "clamp", "regularize"])
def test_stiffness_is_symmetric(dim, fix):
    s, rng = random_system(dim, 11)
    x = s.x0 + 0.05 * rng.standard_normal(s.x0.shape)
    K = s.stiffness_matrix(x, fix=fix)
    assert abs(K - K.T).max() == 0.0


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
@pytest.mark.parametrize("fix", ["clamp", "regularize"])
def test_fixes_make_indefinite_compressed_stiffness_psd(dim, fix):
    s, _ = random_system(dim, 5, compress=True)
    K = s.stiffness_matrix(s.x0).toarray()
    scale = np.abs(K).max()
    assert np.linalg.eigvalsh(K).min() < -1e-3 * scale        # compressed: really indefinite
    Kf = s.stiffness_matrix(s.x0, fix=fix).toarray()
    assert np.linalg.eigvalsh(Kf).min() >= -1e-10 * scale
    if fix == "regularize":
        assert s.last_shift > 0
        assert np.allclose(Kf - K, s.last_shift * np.eye(s.ndof))


def test_clamp_changes_nothing_for_stretched_springs():
    s, _ = random_system(3, 4, contacts=False)
    x = s.x0 * 1.0
    stretched = MassSpringSystem(x, s.mass, s.springs, s.k, rest=0.5 * np.linalg.norm(
        x[s.springs[:, 1]] - x[s.springs[:, 0]], axis=1))
    K = stretched.stiffness_matrix(x)
    assert abs(K - stretched.stiffness_matrix(x, fix="clamp")).max() == 0.0
    assert stretched.regularization_shift(x) == 0.0


def test_spring_block_eigenvalues_by_hand():
    # eigenvalues of k[(1 - L/l)(I - uu^T) + uu^T]: k along u, k(1 - L/l) across
    u = np.array([[0.6, 0.8, 0.0]])
    H = spring_blocks(np.array([2.0]), u, 3.0, 5.0)[0]
    ev = np.sort(np.linalg.eigvalsh(H))
    assert np.allclose(ev, [3.0 * (1 - 5.0 / 2.0)] * 2 + [3.0])
    assert np.allclose(H @ u[0], 3.0 * u[0])


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
@pytest.mark.parametrize("fix", [None, "clamp", "regularize"], ids=["nofix", "clamp", "regularize"])
def test_hessian_product_equals_assembled_product(dim, fix):
    s, rng = random_system(dim, 21)
    x = s.x0 + 0.05 * rng.standard_normal(s.x0.shape)
    d = rng.standard_normal(x.shape)
    K = s.stiffness_matrix(x, fix=fix)
    assert np.allclose(s.hessian_product(x, d, fix=fix).ravel(), K @ d.ravel(), rtol=1e-12, atol=1e-12)


def test_unknown_fix_is_named():
    s, _ = random_system(2, 1)
    with pytest.raises(UnknownNameError, match="clamp"):
        s.stiffness_matrix(s.x0, fix="eigen")


def test_pattern_reused_and_matches_dense_assembly():
    s, rng = random_system(2, 3, contacts=False)
    x = s.x0 + 0.05 * rng.standard_normal(s.x0.shape)
    K1 = s.stiffness_matrix(x)
    pat = s.pattern
    K2 = s.stiffness_matrix(x + 0.01)
    assert s.pattern is pat
    # independent dense assembly, block by block
    dense = np.zeros((s.ndof, s.ndof))
    for (i, j), k, L in zip(s.springs, s.k, s.rest):
        dx = x[j] - x[i]
        l = np.linalg.norm(dx)
        u = dx / l
        H = k * (np.eye(2) - L / l * (np.eye(2) - np.outer(u, u)))
        for a, b, sign in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            dense[2 * a:2 * a + 2, 2 * b:2 * b + 2] += sign * H
    assert np.allclose(K1.toarray(), dense, rtol=1e-13, atol=1e-12)
    assert K2.nnz == K1.nnz
