"""Barrier contact (IPC through ipctk): derivatives in femkit's conventions, the independent
intersection test, the integrator trait, and dynamics that must never penetrate.

Every trajectory here is checked frame by frame by :func:`femkit.contact.check.intersecting_pairs`
(numpy, no ipctk) and by its minimum distance (> 0).
"""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

pytest.importorskip("ipctk")

from femkit.contact import body_surface, plane_obstacle
from femkit.contact.barrier import BarrierModel
from femkit.contact.check import intersecting_pairs
from femkit.dynamics.forces import BarrierContact, Gravity
from femkit.dynamics.integrators import INTEGRATORS, StepContext
from femkit.dynamics.system import MassSpringSystem, elastic_system
from femkit.errors import InputError
from femkit.solids import ElasticBody, StableNeoHookean

from _bodies import cube, merged  # noqa: E402


def _fd(energy, gradient, hessian, x, h=1e-7):
    """Relative errors of ``gradient`` against central differences of ``energy`` and of
    ``hessian`` against central differences of ``gradient``."""
    g, H = gradient(x).ravel(), hessian(x)
    gn, Hn = np.zeros_like(g), np.zeros_like(H)
    for k in range(g.size):
        e = np.zeros(g.size)
        e[k] = h
        gn[k] = (energy(x.ravel() + e) - energy(x.ravel() - e)) / (2 * h)
        Hn[:, k] = (gradient(x.ravel() + e).ravel() - gradient(x.ravel() - e).ravel()) / (2 * h)
    return np.abs(g - gn).max() / np.abs(g).max(), np.abs(H - Hn).max() / np.abs(H).max()


def _tet_system(mu=0.0):
    X = np.array([[0, 0, 0.002], [1, 0, 0.003], [0, 1, 0.0025], [0.3, 0.3, 1.0]]) + [0.37, 0.21, 0]
    force = BarrierContact(body_surface([[0, 1, 2, 3]], 3),
                           [plane_obstacle([0.05, 0.1, 0], [0, 0, 1.0], 5.0, 3)],
                           dhat=0.01, stiffness=7.0, mu=mu, eps_v=1e-2)
    s = MassSpringSystem(X, 1.0, np.zeros((0, 2), int), 0.0, forces=[force])
    return s, s.forces[0]


def test_barrier_force_is_minus_the_gradient_of_its_energy_and_its_stiffness_the_hessian():
    s, f = _tet_system()
    assert f.model.active(s.x0) >= 3
    def force(x):
        out = np.zeros((4, 3))
        f.add_force(np.asarray(x).reshape(4, 3), None, 0.0, out)
        return -out
    eg, eh = _fd(lambda x: f.energy(x.reshape(4, 3)), force,
                 lambda x: f.stiffness(x, None).toarray(), s.x0)
    assert eg < 1e-6 and eh < 1e-6
    # the clamped Hessian is PSD, the exact one is not everywhere
    assert np.linalg.eigvalsh(f.stiffness(s.x0, "clamp").toarray()).min() > -1e-9


def test_lagged_friction_derivatives_and_its_coulomb_magnitude():
    s, f = _tet_system(mu=0.4)
    x0 = s.x0
    f.begin_step(x0, 0.01, lambda x: np.zeros(x.size))
    x = x0.copy()
    x[:3, 0] += 0.003      # slide the near face along x, far above eps_v h
    m = f.model
    eg, eh = _fd(m._friction_energy, m._friction_gradient,
                 lambda y: m._friction_hessian(y, m._ipc.PSDProjectionMethod.NONE).toarray(), x)
    assert eg < 1e-6 and eh < 1e-6
    normal = -(m.kappa_value * m.barrier_gradient(x0))[:3, 2]
    friction = np.linalg.norm(m._friction_gradient(x)[:3].sum(axis=0))
    assert friction == pytest.approx(0.4 * normal.sum(), rel=2e-2)   # mu lambda once sliding
    f.end_step()
    assert m._friction_energy(x) == 0.0


def test_the_independent_check_finds_what_ipctk_finds():
    import ipctk

    rng = np.random.default_rng(3)
    agree = 0
    for _ in range(40):
        V = rng.random((6, 3))
        F = np.array([[0, 1, 2], [3, 4, 5]])
        mine = len(intersecting_pairs(V, F)) > 0
        theirs = ipctk.has_intersections(ipctk.CollisionMesh(V, ipctk.edges(F), F), V)
        agree += mine == theirs
    assert agree == 40
    V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [.2, .2, -1], [.2, .2, 1], [.9, .9, 1]])
    assert intersecting_pairs(V, [[0, 1, 2], [3, 4, 5]]).tolist() == [[0, 1]]
    V[3:, 2] += 1.5
    assert len(intersecting_pairs(V, [[0, 1, 2], [3, 4, 5]])) == 0


@pytest.mark.parametrize("name", INTEGRATORS.names())
def test_an_integrator_refuses_barrier_contact_unless_it_keeps_it(name):
    s, _ = _tet_system()
    integ = INTEGRATORS.get(name)()
    if integ.keeps_contact:
        integ.start(s, s.x0, s.v0, 0.0, 1e-3, StepContext())
    else:
        with pytest.raises(InputError, match="newton"):
            integ.start(s, s.x0, s.v0, 0.0, 1e-3, StepContext())


@pytest.mark.parametrize("kw, word", [({"dhat": 0.0}, "dhat"), ({"mu": -0.1}, "friction"),
                                      ({"eps_v": -1.0}, "eps_v"), ({"lagging": 0}, "lagging"),
                                      ({"ccd": "exact"}, "tight_inclusion, additive")])
def test_bad_contact_parameters_are_one_line_errors(kw, word):
    with pytest.raises(InputError, match=word):
        BarrierModel(np.eye(3, 3), [[0, 1, 2]], **kw)


def _run(system, steps, dt, **options):
    integ = INTEGRATORS.get("newton")(**{"tol": 1e-8, **options})
    ctx = StepContext()
    st = integ.start(system, system.x0, system.v0, 0.0, dt, ctx)
    f = next(g for g in system.forces if isinstance(g, BarrierContact))
    frames = [st]
    for _ in range(steps):
        st = integ.step(system, st, dt, ctx)
        frames.append(st)
        assert f.model.intersections(st.x) == 0
        d = f.model.min_distance(st.x)
        assert d is None or d > 0.0
    return frames, f


def _body(P, T, E=2e4, density=1000.0):
    return ElasticBody(P, T, StableNeoHookean.from_young(E, 0.3, density=density))


def test_an_elastic_cube_dropped_on_a_plane_rebounds_and_rests_at_the_barrier_gap():
    P, T = cube(1, 0.2, (0.0, 0.0, 0.02))
    # the plane's two triangles meet on the line x + y = 0.23: no corner of the cube rests right
    # above that inner edge (on x + y = 0.2 two did, and the near-degenerate point-edge pairs
    # there pushed sideways at a 1e-8 gap: a frictionless drift left at rest)
    force = BarrierContact(body_surface(T, 3), [plane_obstacle([0.13, 0.1, 0], [0, 0, 1], 1.0, 3)])
    s = elastic_system(_body(P, T, E=1e5), forces=[Gravity(9.81), force],
                       v0=np.tile([0.0, 0.0, -1.0], (len(P), 1)))
    frames, f = _run(s, 70, 2e-3)
    vz = np.array([fr.v[:, 2].mean() for fr in frames])
    zmin = np.array([fr.x[:, 2].min() for fr in frames])
    impact = int(np.argmax(zmin < f.model.dhat))
    assert impact > 0 and vz[impact:].max() > 0.2     # it bounces back up
    assert zmin.min() > 0.0                           # never below the plane
    frames2, _ = _run(s, 25, 0.1)                    # large steps: it settles
    gap = frames2[-1].x[:, 2].min()
    assert 0.0 < gap < f.model.dhat and abs(frames2[-1].v).max() < 1e-3


def test_two_equal_bodies_head_on_conserve_momentum_and_never_gain_energy():
    a = cube(1, 0.2, (0.0, 0.0, 0.0))
    b = cube(1, 0.2, (0.25, 0.03, 0.02))
    P, T, (ra, rb) = merged(a, b)
    v0 = np.zeros_like(P)
    v0[ra, 0], v0[rb, 0] = 1.0, -1.0
    v0[ra, 1] = 0.3
    s = elastic_system(_body(P, T), forces=[BarrierContact(body_surface(T, 3))], v0=v0)
    frames, f = _run(s, 40, 2e-3)
    p0 = s.momentum(s.v0)
    scale = np.abs(s.mass[:, None] * s.v0).sum()
    energy = [s.energies(fr.x, fr.v)["total"] for fr in frames]
    assert max(f.model.active(fr.x) for fr in frames) > 0          # they did touch
    for fr in frames:
        assert np.abs(s.momentum(fr.v) - p0).max() <= 1e-8 * scale
    assert all(e1 <= e0 * (1 + 1e-9) for e0, e1 in zip(energy, energy[1:]))
    assert frames[-1].v[ra, 0].mean() < 0.5       # they pushed each other back


@pytest.mark.parametrize("theta, mu", [(0.3, 0.5), (0.5, 0.2)])
def test_a_block_on_an_incline_sticks_below_the_friction_angle_and_slides_above_it(theta, mu):
    P, T = cube(1, 0.1, (0.0, 0.0, 5e-4))
    g = 9.81
    gravity = Gravity([g * np.sin(theta), 0.0, -g * np.cos(theta)])   # the plane tilted by theta
    force = BarrierContact(body_surface(T, 3), [plane_obstacle([0.05, 0.05, 0], [0, 0, 1], 5.0, 3)],
                           dhat=1e-3, mu=mu, eps_v=1e-4, lagging=2)
    s = elastic_system(_body(P, T, E=1e6), forces=[gravity, force])
    dt = 5e-3
    frames, _ = _run(s, 30, dt)
    vx = np.array([fr.v[:, 0].mean() for fr in frames])
    if np.tan(theta) < mu:   # once the normal force holds it: at rest (smooth friction creeps
        assert np.abs(vx[15:]).max() < 2e-4          # at speeds of order eps_v = 1e-4)
        assert np.ptp([fr.x[:, 0].mean() for fr in frames[15:]]) < 15 * dt * 2e-4
    else:
        a = np.polyfit(dt * np.arange(15, 31), vx[15:], 1)[0]
        assert a == pytest.approx(g * (np.sin(theta) - mu * np.cos(theta)), rel=0.02)


def test_a_2d_body_on_its_boundary_segments_lands_on_a_line_without_crossing_it():
    from femkit.mesh import structured_mesh

    mesh = structured_mesh(3, 3, 0.2, 0.2, origin=(0.0, 0.01))
    P, T = np.asarray(mesh.points, float), np.asarray(mesh.triangles)
    surface = body_surface(T, 2)
    assert surface.shape == (12, 2)                      # the square's 12 boundary segments
    force = BarrierContact(surface, [plane_obstacle([0.1, 0.0], [0.0, 1.0], 1.0, 2)])
    s = elastic_system(_body(P, T, E=1e5), forces=[Gravity(9.81), force],
                       v0=np.tile([0.3, -1.0], (len(P), 1)))
    frames, f = _run(s, 25, 2e-3)
    assert max(f.model.active(fr.x) for fr in frames) > 0
    assert min(fr.x[:, 1].min() for fr in frames) > 0.0


def test_a_moving_plane_pushes_a_block_and_never_passes_through_it():
    from dataclasses import replace

    P, T = cube(1, 0.2, (0.0, 0.0, 0.0))
    dhat = 1e-3 * np.linalg.norm(np.ptp(P, axis=0))
    speed = 0.5   # 5 mm per step: about 15 dhat, many CCD-bounded moves within each step
    wall = replace(plane_obstacle([-0.5 * dhat, 0.1, 0.1], [1, 0, 0], 1.0, 3),
                   velocity=np.array([speed, 0.0, 0.0]))
    s = elastic_system(_body(P, T, E=1e5), forces=[BarrierContact(body_surface(T, 3), [wall])])
    frames, f = _run(s, 5, 0.01, tol=1e-6)
    t = frames[-1].t
    # the wall is where its motion puts it, and the block ahead of it (pushed, not crossed)
    assert np.allclose(f.model.static, f.model.static0 + t * np.array([speed, 0.0, 0.0]))
    wall_x = f.model.static[0, 0]
    assert wall_x == pytest.approx(speed * t - 0.5 * dhat)
    assert frames[-1].x[:, 0].min() > wall_x
    assert frames[-1].v[:, 0].mean() > 0.5 * speed
    with pytest.raises(InputError, match="moving obstacle"):
        from femkit.solids import solve_static
        solve_static(_body(P, T), contact=f.model)


def test_additive_ccd_keeps_a_fast_cube_off_the_plane():
    # 2 m/s onto the plane at dt 0.01: the first step would pass 10 cube widths through it
    P, T = cube(1, 0.2, (0.0, 0.0, 0.02))
    force = BarrierContact(body_surface(T, 3), [plane_obstacle([0.13, 0.1, 0], [0, 0, 1], 1.0, 3)],
                           ccd="additive")
    s = elastic_system(_body(P, T, E=1e5), forces=[Gravity(9.81), force],
                       v0=np.tile([0.0, 0.0, -2.0], (len(P), 1)))
    frames, f = _run(s, 6, 1e-2, tol=1e-6)
    assert f.model.ccd_method == "additive"
    assert min(fr.x[:, 2].min() for fr in frames) > 0.0
    assert frames[-1].v[:, 2].mean() > -1.0          # stopped (or thrown back) by the plane


def test_two_bodies_in_contact_run_on_the_cholesky_solver_as_on_superlu():
    # their contact Hessian couples nodes of both bodies, outside the springs' and elements'
    # compiled pattern of the cholesky path (which refused it): it goes on the run's
    # ContactPattern, the iterates those of SuperLU on the generally assembled matrix
    pytest.importorskip("cholespy", reason="cholespy is not installed: pip install -e '.[fast]'")
    from femkit.solvers.spec import SolverSpec

    a, b = cube(1, 0.2, (0.0, 0.0, 0.0)), cube(1, 0.2, (0.21, 0.03, 0.02))
    P, T, (ra, rb) = merged(a, b)
    v0 = np.zeros_like(P)
    v0[ra, 0], v0[rb, 0] = 1.0, -1.0
    runs = []
    for spec in (SolverSpec("direct"), SolverSpec("cholesky", options={"engine": "cholespy"})):
        s = elastic_system(_body(P, T), forces=[BarrierContact(body_surface(T, 3))], v0=v0)
        integ, ctx = INTEGRATORS.get("newton")(tol=1e-8), StepContext(spec)
        st = integ.start(s, s.x0, s.v0, 0.0, 2e-3, ctx)
        model = next(g for g in s.forces if isinstance(g, BarrierContact)).model
        for _ in range(8):
            st = integ.step(s, st, 2e-3, ctx)
            assert model.intersections(st.x) == 0
        assert model.active(st.x) > 0                              # they touch
        assert ("contact_pattern" in ctx.cache) == (spec.method == "cholesky")
        runs.append(st.x)
    assert np.abs(runs[1] - runs[0]).max() <= 1e-9


class _Bound:
    """A force whose CCD allows this fraction of any move (the newton step's only other input)."""

    def __init__(self, fraction):
        self.fraction, self.moves = fraction, []

    def step_bound(self, x0, x1):
        self.moves.append(np.abs(x1 - x0).max())
        return self.fraction


def test_a_full_contact_step_on_a_linear_stretch_is_extended_as_far_as_ccd_allows():
    from femkit.dynamics.integrators.newton import EXTRAPOLATE_MAX

    integ = INTEGRATORS.get("newton")()
    x, dx = np.zeros(3), np.array([1.0, 0.0, 0.0])
    g = lambda z: (-z[0], 0.0)                        # falls linearly along dx: no minimum near
    slope, (g1, _) = -1.0, g(x + dx)
    for fraction, far in ((1.0, EXTRAPOLATE_MAX), (0.25, 0.25 * EXTRAPOLATE_MAX)):
        f = _Bound(fraction)
        t, x_t, g_t, _ = integ._extrapolate(g, [f], (3,), x, dx, slope, 0.0, 1.0, x + dx, g1, 0.0)
        assert t == pytest.approx(far) and x_t[0] == pytest.approx(far) and g_t < g1
        assert f.moves == [pytest.approx(EXTRAPOLATE_MAX)]     # CCD over the extended move
    # a quadratic the full step already minimises (decrease 1/2 of the linear model's): kept
    q = lambda z: (0.5 * z[0] ** 2 - z[0], 0.0)
    f = _Bound(1.0)
    t, *_ = integ._extrapolate(q, [f], (3,), x, dx, -1.0, 0.0, 1.0, x + dx, -0.5, 0.0)
    assert t == 1.0 and f.moves == []


def test_a_contact_step_starts_towards_the_inertial_prediction_as_far_as_ccd_allows():
    integ = INTEGRATORS.get("newton")()
    xn, y = np.zeros(3), np.array([2.0, 0.0, 0.0])
    down = lambda z: (-z[0], 0.0)                     # lower towards y: start at CCD's bound
    x, gx, _ = integ._warm_start(down, [_Bound(0.25)], (3,), xn, y)
    assert x[0] == pytest.approx(0.5) and gx == pytest.approx(-0.5)
    up = lambda z: (z[0], 0.0)                        # higher there: start where the step began
    x, gx, _ = integ._warm_start(up, [_Bound(1.0)], (3,), xn, y)
    assert np.array_equal(x, xn) and gx == 0.0
