"""MassSpringSystem: Hooke force by hand, energies, momentum, pins, Liu's L and J, bad input."""

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity, GroundContact
from femkit.dynamics.system import MassSpringSystem
from femkit.errors import InputError


def test_one_spring_force_by_hand():
    # x_ij = (3, 4), l = 5, L = 2, k = 7: f_i = 7 * 3 * (0.6, 0.8) = (12.6, 16.8), f_j = -f_i
    s = MassSpringSystem([[1.0, 1.0], [4.0, 5.0]], 1.0, [[0, 1]], 7.0, rest=2.0)
    f = s.force(s.x0, s.v0)
    assert np.allclose(f, [[12.6, 16.8], [-12.6, -16.8]], rtol=1e-15)
    assert s.energies(s.x0, s.v0)["spring"] == pytest.approx(0.5 * 7 * 3 ** 2)


def test_compressed_spring_pushes_apart_3d():
    s = MassSpringSystem([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], 1.0, [[0, 1]], 2.0, rest=1.5)
    assert np.allclose(s.force(s.x0, s.v0), [[0, 0, -1.0], [0, 0, 1.0]])


def test_dashpot_along_spring_by_hand():
    # u = (1, 0); v_j - v_i = (-2, 5): only the axial part -2 counts, f_i = c (-2) u
    s = MassSpringSystem([[0.0, 0.0], [1.0, 0.0]], 1.0, [[0, 1]], 1.0, damping=0.5)
    v = np.array([[1.0, 0.0], [-1.0, 5.0]])
    assert np.allclose(s.force(s.x0, v), [[-1.0, 0.0], [1.0, 0.0]])


def test_default_rest_is_initial_length_so_no_force():
    rng = np.random.default_rng(0)
    x0 = rng.random((5, 3))
    s = MassSpringSystem(x0, 1.0, [[0, 1], [1, 2], [2, 3], [3, 4], [0, 4]], 10.0)
    assert np.abs(s.force(x0, s.v0)).max() < 1e-13


def _random(dim, draw, pinned=None, forces=()):
    rng = np.random.default_rng(draw)
    n = 10
    x0 = rng.random((n, dim))
    a, b = np.triu_indices(n, 1)
    keep = rng.random(len(a)) < 0.4
    sp = np.stack([a[keep], b[keep]], 1)
    s = MassSpringSystem(x0, rng.uniform(0.5, 2, n), sp, rng.uniform(1, 4, len(sp)),
                         rest=rng.uniform(0.2, 1.0, len(sp)), damping=rng.uniform(0, 1, len(sp)),
                         pinned=pinned, forces=forces)
    return s, rng


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_force_is_minus_energy_gradient(dim):
    s, rng = _random(dim, 3, pinned=[2], forces=[Gravity(9.81), GroundContact(50.0, height=0.3)])
    x = s.x0 + 0.01 * rng.standard_normal(s.x0.shape)
    h = 1e-6
    g = np.zeros(s.ndof)
    for c in range(s.ndof):
        e = np.zeros(s.ndof)
        e[c] = h
        g[c] = (s.potential_energy((x.ravel() + e).reshape(x.shape))
                - s.potential_energy((x.ravel() - e).reshape(x.shape))) / (2 * h)
    free = s.free_dofs
    f = s.force(x, np.zeros_like(x)).ravel()
    assert np.allclose(-g[free], f[free], rtol=1e-7, atol=1e-7 * np.abs(f).max())
    assert np.allclose(s.potential_gradient(x).ravel(), -f)
    e = s.energies(x, np.zeros_like(x))
    assert e["contact"] > 0 and e["gravity"] != 0


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_internal_forces_conserve_momentum(dim):
    s, rng = _random(dim, 4)
    x = s.x0 + 0.1 * rng.standard_normal(s.x0.shape)
    v = rng.standard_normal(x.shape)
    f = s.force(x, v)
    assert np.abs(f).max() > 1.0
    assert np.abs(f.sum(axis=0)).max() < 1e-12 * np.abs(f).max() * s.n_springs


def test_pinned_rows_zero_and_mask_from_indices_or_bool():
    s, rng = _random(3, 5, pinned=[0, 3], forces=[Gravity(9.81)])
    f = s.force(s.x0, rng.standard_normal(s.x0.shape))
    assert np.all(f[[0, 3]] == 0) and np.all(np.abs(f[[1, 2]]).sum(1) > 0)
    assert np.all(s.acceleration(s.x0, s.v0)[[0, 3]] == 0)
    mask = np.zeros(s.n, bool)
    mask[[0, 3]] = True
    s2 = MassSpringSystem(s.x0, s.mass, s.springs, s.k, s.rest, pinned=mask)
    assert np.array_equal(s2.pinned, s.pinned)
    assert len(s.free_dofs) == 3 * (s.n - 2) and not np.isin([0, 1, 2, 9, 10, 11], s.free_dofs).any()


def test_acceleration_is_force_over_mass():
    s, rng = _random(2, 6, forces=[Gravity(3.0)])
    v = rng.standard_normal(s.x0.shape)
    assert np.allclose(s.acceleration(s.x0, v) * s.mass[:, None], s.force(s.x0, v))


def test_energies_and_momentum_by_hand():
    s = MassSpringSystem([[0.0, 0.0], [0.0, 2.0]], [1.0, 3.0], [[0, 1]], 4.0, rest=1.0, forces=[Gravity(10.0)])
    v = np.array([[1.0, 0.0], [0.0, -2.0]])
    e = s.energies(s.x0, v)
    assert e["kinetic"] == pytest.approx(0.5 * 1 + 0.5 * 3 * 4)
    assert e["spring"] == pytest.approx(0.5 * 4 * 1)
    assert e["gravity"] == pytest.approx(3 * 10 * 2)
    assert e["contact"] == 0.0
    assert e["total"] == pytest.approx(6.5 + 2 + 60)
    assert np.allclose(s.momentum(v), [1.0, -6.0])


def test_mass_matrix_and_laplacian_and_liu_terms():
    s, rng = _random(3, 8)
    M = s.mass_matrix()
    assert np.allclose(M.diagonal(), np.repeat(s.mass, 3))
    L = s.spring_laplacian().toarray()
    A = np.zeros((s.n, s.n_springs))
    A[s.springs[:, 0], np.arange(s.n_springs)] = 1
    A[s.springs[:, 1], np.arange(s.n_springs)] = -1
    assert np.allclose(L, A @ np.diag(s.k) @ A.T)
    assert np.allclose(s.spring_J().toarray(), A @ np.diag(s.k))
    # Liu: gradient of 1/2 sum k |(x_i - x_j) - d_s|^2 is L x - J d, and equals the Hooke
    # spring force's negative when d_s is the local-step projection
    x = s.x0 + 0.05 * rng.standard_normal(s.x0.shape)
    d = s.spring_directions(x)
    assert np.allclose(np.linalg.norm(d, axis=1), s.rest)
    grad = L @ x - s.spring_J() @ d
    assert np.allclose(-grad, s.spring_forces(x), atol=1e-12)


def test_zero_length_spring_is_finite():
    s = MassSpringSystem([[0.0, 0.0], [1.0, 0.0]], 1.0, [[0, 1]], 5.0, rest=1.0)
    x = np.array([[0.5, 0.5], [0.5, 0.5]])
    assert np.all(np.isfinite(s.force(x, s.v0)))
    assert np.all(np.isfinite(s.stiffness_matrix(x).data))
    assert np.all(np.isfinite(s.stiffness_matrix(x, fix="regularize").data))
    assert np.isfinite(s.energies(x, s.v0)["total"])


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(x0=[[0.0, 0.0], [0.0, 0.0]], springs=[[0, 1]]), "coincident"),
        (dict(springs=[[0, 0]]), "itself"),
        (dict(springs=[[0, 5]]), r"\[0, 1\]"),
        (dict(mass=[1.0, 0.0]), "mass must be > 0"),
        (dict(k=-1.0), "stiffness"),
        (dict(x0=[[0.0, np.nan], [1.0, 0.0]]), "finite"),
        (dict(x0=[0.0, 1.0]), "shape"),
        (dict(springs=[[0.5, 1.0]]), "integer"),
        (dict(pinned=[7]), "pinned"),
        (dict(v0=np.zeros((3, 2))), "v0"),
    ],
    ids=["zero-rest", "self-spring", "index-range", "zero-mass", "negative-k", "nan-x0", "flat-x0",
         "float-springs", "pin-range", "v0-shape"],
)
def test_bad_input_raises_input_error(kwargs, match):
    args = dict(x0=[[0.0, 0.0], [1.0, 0.0]], mass=1.0, springs=[[0, 1]], k=1.0)
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        MassSpringSystem(args.pop("x0"), args.pop("mass"), args.pop("springs"), args.pop("k"), **args)


def test_state_shape_checked_and_flat_accepted():
    s = MassSpringSystem([[0.0, 0.0], [2.0, 0.0]], 1.0, [[0, 1]], 1.0, rest=1.0)
    assert np.allclose(s.force(s.x0.ravel(), s.v0), s.force(s.x0, s.v0))
    with pytest.raises(InputError, match="shape"):
        s.force(np.zeros((3, 2)), s.v0)


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_force_splits_into_springs_constant_and_variable(dim):
    from femkit.dynamics.forces import RayleighDamping, ViscousDamping

    forces = [Gravity(9.81), GroundContact(50.0, height=0.3), ViscousDamping(0.7),
              RayleighDamping(0.2, 0.01)]
    s, rng = _random(dim, 5, pinned=[1], forces=forces)
    s = MassSpringSystem(s.x0, s.mass, s.springs, s.k, s.rest, damping=0.3, pinned=[1], forces=forces)
    x = s.x0 + 0.2 * rng.standard_normal(s.x0.shape)
    v = rng.standard_normal(s.x0.shape)
    hooke = s.spring_forces(x)
    hooke[s.pinned] = 0.0
    total = hooke + s.constant_force() + s.variable_force(x, v, 0.5)
    np.testing.assert_allclose(total, s.force(x, v, 0.5), rtol=1e-13, atol=1e-12)
    assert s.has_variable_forces
    g = s.constant_force()
    assert np.all(g[s.pinned] == 0.0) and np.all(g[~s.pinned, -1] < 0.0)
    plain = MassSpringSystem(s.x0, s.mass, s.springs, s.k, s.rest, forces=[Gravity(9.81)])
    assert not plain.has_variable_forces
    assert np.all(plain.variable_force(x, v) == 0.0)
