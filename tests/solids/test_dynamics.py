"""An elastic solid through femkit's dynamics: every registered integrator runs it unchanged;
implicit midpoint keeps an undamped beam's energy, implicit Euler dissipates it monotonically;
a damped implicit run comes to rest at the quasi-static equilibrium."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity, RayleighDamping
from femkit.dynamics.forces.elastic import ElasticForce
from femkit.dynamics.system import elastic_system
from femkit.dynamics.integrators import INTEGRATORS
from femkit.dynamics.simulate import simulate
from femkit.errors import InputError, InstabilityError
from femkit.mesh.structured import structured_box
from femkit.solids import ElasticBody, material
from femkit.solids.boundary import Dirichlet, body_forces, tagged_nodes
from femkit.solids.static import solve_static


def _beam(nx=2, name="stable_neo_hookean"):
    mesh = structured_box(nx, 1, 1, (float(nx), 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material(name, E=1e3, nu=0.3, density=1.0))
    return mesh, body, tagged_nodes(mesh, "xmin")


def _bent(body):
    x0 = body.rest_positions.copy()
    x0[:, 2] -= 0.03 * x0[:, 0] ** 2
    return x0


# projective dynamics integrates its own (ARAP) energy: checked against Newton on that energy in
# tests/dynamics/test_projective.py
@pytest.mark.parametrize("name", sorted(n for n in INTEGRATORS
                                        if not getattr(INTEGRATORS.get(n), "solids_only", False)))
def test_every_integrator_runs_an_elastic_beam(name):
    mesh, body, clamp = _beam()
    system = elastic_system(body, x0=_bent(body), pinned=clamp)
    dt, t_end = 2e-3, 0.04                               # below the explicit limit 2 / omega_max
    assert dt < 2.0 / system.omega_max()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = simulate(system, name, dt, t_end)
        ref = simulate(system, "rk4", dt / 4, t_end)
    tip = np.flatnonzero(np.isclose(body.rest_positions[:, 0], 2.0))
    rise, rise_ref = (t.x[-1][tip, 2] - t.x[0][tip, 2] for t in (tr, ref))
    assert np.all(np.isfinite(tr.x[-1]))
    np.testing.assert_array_equal(tr.x[-1][clamp], body.rest_positions[clamp])
    assert np.all(rise_ref > 0)                          # the elastic force lifts the bent tip
    # every method follows the same motion (first-order methods to their O(dt) error)
    assert np.abs(rise - rise_ref).max() <= 0.1 * np.abs(rise_ref).max()


def _energy_run(method, steps):
    mesh, body, clamp = _beam()
    system = elastic_system(body, x0=_bent(body), pinned=clamp)
    tr = simulate(system, method, 2e-3, steps * 2e-3)
    return tr.energies["total"]


@pytest.mark.slow
def test_implicit_midpoint_keeps_the_undamped_beam_energy():
    e = _energy_run("variational_symplectic", 1000)
    assert len(e) == 1001
    assert np.abs(e / e[0] - 1.0).max() <= 1e-3          # measured ~4e-7


@pytest.mark.slow
def test_implicit_euler_dissipates_monotonically():
    for method in ("implicit_euler", "newton"):
        e = _energy_run(method, 300)
        assert np.all(np.diff(e) <= 1e-12 * e[0])
        assert e[-1] < 0.95 * e[0]


def test_damped_run_settles_at_the_static_equilibrium():
    mesh, body, clamp = _beam(3)
    g = 9.81
    static = solve_static(body, Dirichlet(body.n, 3).fix(clamp),
                          body_forces(body, body.density()[:, None] * np.array([0.0, 0.0, -g])))
    system = elastic_system(body, pinned=clamp, forces=[Gravity(g), RayleighDamping(alpha=5.0)])
    tr = simulate(system, "newton", 0.5, 20.0)
    scale = np.abs(static.u).max()
    assert scale > 1e-3
    assert np.abs(tr.x[-1] - static.x).max() <= 1e-6 * scale


def test_elastic_force_matches_the_body_and_refuses_another_mesh():
    mesh, body, clamp = _beam()
    system = elastic_system(body, x0=_bent(body))
    x = system.x0
    np.testing.assert_allclose(system.force(x, 0 * x), -body.gradient(x), atol=1e-12)
    K = system.stiffness_matrix(x, fix="clamp").toarray()
    np.testing.assert_allclose(K, body.hessian(x, project=True).toarray(), atol=1e-12)
    assert system.energies(x, 0 * x)["spring"] == pytest.approx(body.energy(x), rel=1e-14)
    other = structured_box(1, 1, 1)
    with pytest.raises(InputError, match="nodes"):
        elastic_system(ElasticBody.from_mesh(other, body.materials[0]), x0=x)
    with pytest.raises(InputError, match="elastic body"):
        from femkit.dynamics.system import MassSpringSystem

        MassSpringSystem(other.points, 1.0, np.zeros((0, 2), int), 0.0, forces=[ElasticForce(body)])


@pytest.mark.parametrize("name,recovers", [("stable_neo_hookean", True), ("corotational", True),
                                           ("stvk", False)])
def test_tetrahedron_pressed_through_itself(name, recovers):
    """Apex pushed through the pinned base, released with damping (Newton implicit Euler).
    Stable neo-Hookean (and co-rotational on signed stretches) recover; StVK settles in the mirror
    image, which it finds stress-free (F = diag(1, 1, -1): F^T F = I), and stays inverted --
    reported by ``inverted`` naming the element, never a NaN."""
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    body = ElasticBody(X, [[0, 1, 2, 3]], material(name, E=100.0, nu=0.3))
    x0 = X.copy()
    x0[3, 2] = -0.5
    assert body.inverted(x0).tolist() == [0]
    system = elastic_system(body, x0=x0, pinned=[0, 1, 2], forces=[RayleighDamping(alpha=2.0)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = simulate(system, "newton", 0.05, 5.0)
    assert np.all(np.isfinite(tr.x)) and np.all(np.isfinite(tr.energies["total"]))
    end = tr.x[-1]
    assert body.energy(end) <= 1e-10 * body.materials[0].mu
    if recovers:
        assert body.inverted(end).size == 0 and end[3, 2] == pytest.approx(1.0, abs=1e-6)
    else:
        assert body.inverted(end).tolist() == [0] and end[3, 2] == pytest.approx(-1.0, abs=1e-6)


@pytest.mark.parametrize("name", ["linear", "stable_neo_hookean"])
def test_explicit_critical_step_from_the_stability_module(name):
    """Velocity Verlet is stable for ``dt omega_max < 2``: 5% below the step predicted by
    ``omega_max`` (largest eigenvalue of ``M^-1 K``, power iteration) the energy stays bounded,
    5% above it the run is stopped as unstable (small random start: the linearisation is what counts)."""
    mesh, body, clamp = _beam(2, name)
    rng = np.random.default_rng(3)
    v0 = 1e-6 * rng.standard_normal(body.rest_positions.shape)
    system = elastic_system(body, pinned=clamp, v0=v0)
    dt_crit = 2.0 / system.omega_max()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = simulate(system, "velocity_verlet", 0.95 * dt_crit, 400 * dt_crit)
        e = tr.energies["total"]
        # bounded: near the limit Verlet's shadow energy differs from E by up to 1 / (1 - (h w / 2)^2) ~ 10
        assert tr.completed and e.max() <= 20.0 * e[0]
        with pytest.raises(InstabilityError) as info:     # femkit's own verdict on the run
            simulate(system, "velocity_verlet", 1.05 * dt_crit, 400 * dt_crit)
    assert info.value.dt_crit == pytest.approx(dt_crit, rel=1e-6)


@pytest.mark.slow
def test_neo_hookean_keeps_volume_where_springs_on_the_same_mesh_lose_it():
    """A 1 x 1 block (10 x 10 cells, criss-cross triangles) sagging under its own weight on a
    pinned base, damped to rest: stable neo-Hookean with nu = 0.45 against Hooke springs on the
    same edges (``mesh_springs``, k = E, which sags about as much). Measured area changes:
    -1.7% against -5.7% (docs/methods.md)."""
    from femkit.dynamics.topology import mesh_springs
    from femkit.mesh.structured import structured_mesh

    mesh = structured_mesh(10, 10, diagonal="alternating")
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1.0, nu=0.45, density=1.0))
    base = np.flatnonzero(mesh.points[:, 1] == 0.0)
    load = [Gravity(0.2), RayleighDamping(alpha=3.0)]
    solid = elastic_system(body, pinned=base, forces=load)
    springs = mesh_springs(mesh, k=1.0, pinned=base, forces=load)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ends = [simulate(s, "newton", 0.5, 60.0).x[-1] for s in (solid, springs)]
    area0 = mesh.areas().sum()

    def area_change(x):
        e1, e2 = x[mesh.cells[:, 1]] - x[mesh.cells[:, 0]], x[mesh.cells[:, 2]] - x[mesh.cells[:, 0]]
        return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / area0 - 1.0

    sag = [1.0 - x[:, 1].max() for x in ends]
    change = [area_change(x) for x in ends]
    assert 0.8 < sag[1] / sag[0] < 1.5                      # comparable stiffness
    assert abs(change[0]) < 0.02                            # neo-Hookean: within 2%
    assert change[1] < 3.0 * change[0] < 0                  # springs: more than 3x the loss
