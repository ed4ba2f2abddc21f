"""Declared forces: gravity, viscous and Rayleigh damping, ground and sphere penalty contact."""

import numpy as np
import pytest

from femkit.dynamics.forces import GroundContact, Gravity, RayleighDamping, SphereContact, ViscousDamping
from femkit.dynamics.system import MassSpringSystem
from femkit.errors import InputError


def free_particles(x, mass=2.0, forces=(), pinned=None):
    x = np.asarray(x, float)
    return MassSpringSystem(x, mass, np.zeros((0, 2), int), 1.0, forces=forces, pinned=pinned)


def test_nothing_undeclared():
    s = free_particles([[0.0, -5.0], [1.0, 3.0]])
    assert np.all(s.force(s.x0, np.ones_like(s.x0)) == 0)
    assert s.rayleigh == (0.0, 0.0)


@pytest.mark.parametrize("g, dim, expected", [
    (9.81, 2, [0.0, -9.81]), (9.81, 3, [0.0, 0.0, -9.81]), ([1.0, 2.0], 2, [1.0, 2.0]),
], ids=["2d-scalar", "3d-scalar", "vector"])
def test_gravity_direction_and_energy(g, dim, expected):
    s = free_particles(np.eye(2, dim), mass=[1.0, 3.0], forces=[Gravity(g)])
    f = s.force(s.x0, s.v0)
    assert np.allclose(f, np.outer([1.0, 3.0], expected))
    assert s.energies(s.x0, s.v0)["gravity"] == pytest.approx(-np.sum(f * s.x0))


def test_gravity_bad_vector():
    with pytest.raises(InputError, match="3 finite"):
        free_particles(np.zeros((1, 3)), forces=[Gravity([0.0, 1.0])])


@pytest.mark.parametrize("per_mass", [False, True], ids=["absolute", "per-mass"])
def test_viscous_damping(per_mass):
    s = free_particles([[0.0, 0.0], [1.0, 0.0]], mass=[1.0, 4.0], forces=[ViscousDamping(0.5, per_mass=per_mass)])
    v = np.array([[1.0, 2.0], [-3.0, 0.5]])
    c = 0.5 * (np.array([1.0, 4.0]) if per_mass else np.ones(2))
    assert np.allclose(s.force(s.x0, v), -c[:, None] * v)
    assert np.allclose(s.damping_matrix(s.x0).diagonal(), np.repeat(c, 2))


def test_rayleigh_explicit_term_and_exposure():
    rng = np.random.default_rng(2)
    x0 = rng.random((5, 2))
    springs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [0, 2]])
    base = MassSpringSystem(x0, 1.5, springs, 7.0, rest=0.3)
    s = MassSpringSystem(x0, 1.5, springs, 7.0, rest=0.3, forces=[RayleighDamping(0.2, 0.05)])
    v = rng.standard_normal(x0.shape)
    K = base.stiffness_matrix(x0)
    M = base.mass_matrix()
    expected = base.force(x0, v).ravel() - (0.2 * M @ v.ravel() + 0.05 * K @ v.ravel())
    assert np.allclose(s.force(x0, v).ravel(), expected)
    assert np.allclose(s.force(x0, v, rayleigh=False), base.force(x0, v))
    assert s.rayleigh == (0.2, 0.05)
    # Rayleigh is not part of the damping matrix (implicit methods add it themselves)
    assert s.damping_matrix(x0).nnz == 0 or abs(s.damping_matrix(x0)).max() == 0


def test_ground_contact_only_when_penetrating():
    s = free_particles([[0.0, 0.5], [1.0, -0.2], [2.0, 0.0], [3.0, -0.1]], pinned=[3],
                       forces=[GroundContact(100.0)])
    f = s.force(s.x0, s.v0)
    assert np.allclose(f, [[0, 0], [0, 20.0], [0, 0], [0, 0]])
    assert s.energies(s.x0, s.v0)["contact"] == pytest.approx(0.5 * 100 * 0.2 ** 2)
    K = s.stiffness_matrix(s.x0).toarray()
    assert K[3, 3] == pytest.approx(100.0) and np.count_nonzero(K) == 1


def test_tilted_ground_normal_and_height():
    nrm = np.array([1.0, 1.0])
    s = free_particles([[0.0, 0.0], [2.0, 2.0]], forces=[GroundContact(10.0, height=1.0, normal=nrm)])
    # plane n.x = 1 with n = (1,1)/sqrt2: node 0 at depth 1, node 1 outside
    f = s.force(s.x0, s.v0)
    assert np.allclose(f[0], 10.0 * nrm / np.sqrt(2)) and np.all(f[1] == 0)


@pytest.mark.parametrize("dim", [2, 3], ids=["2d", "3d"])
def test_sphere_contact_pushes_out_radially(dim):
    c = np.zeros(dim)
    x = np.zeros((3, dim))
    x[0, 0] = 0.5   # inside, depth 0.5
    x[1, 0] = 1.5   # outside
    x[2, 1] = 0.999999  # barely inside
    s = free_particles(x, forces=[SphereContact(c, 1.0, 40.0)])
    f = s.force(x, np.zeros_like(x))
    assert np.allclose(f[0], 20.0 * np.eye(dim)[0])
    assert np.all(f[1] == 0)
    assert 0 < f[2, 1] < 1e-4


def test_sphere_centre_particle_is_finite():
    s = free_particles([[0.0, 0.0]], forces=[SphereContact([0.0, 0.0], 1.0, 10.0)])
    assert np.all(np.isfinite(s.force(s.x0, s.v0)))
    assert np.all(np.isfinite(s.stiffness_matrix(s.x0).data))


@pytest.mark.parametrize("make, match", [
    (lambda: ViscousDamping(-1.0), "gamma"),
    (lambda: RayleighDamping(alpha=float("nan")), "alpha"),
    (lambda: GroundContact(-5.0), "stiffness"),
    (lambda: SphereContact([0, 0], "big", 1.0), "radius"),
], ids=["viscous", "rayleigh", "ground", "sphere"])
def test_bad_force_parameters(make, match):
    with pytest.raises(InputError, match=match):
        make()


def test_one_force_object_serves_two_systems():
    g = Gravity(10.0)
    a = free_particles([[0.0, 0.0]], mass=1.0, forces=[g])
    b = free_particles([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], mass=2.0, forces=[g])
    assert np.allclose(a.force(a.x0, a.v0), [[0.0, -10.0]])
    assert np.allclose(b.force(b.x0, b.v0), [[0.0, -20.0]] * 3)
