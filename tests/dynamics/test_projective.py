"""Projective dynamics (Bouaziz et al. 2014): its fixed point is the Newton solution of implicit
Euler with the as-rigid-as-possible energy (the co-rotational material with lam = 0), its error
against that solution falls linearly with the iteration count (fitted factor), each sweep
decreases the implicit-Euler objective, the volume-band projection is the nearest point of the
band, and the run record holds iterations and residuals."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity
from femkit.dynamics.system import elastic_system
from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.errors import InputError
from femkit.mesh.structured import structured_box
from femkit.solids import Corotational, ElasticBody

H = 0.05


def _scene(mu: float = 30.0):
    mesh = structured_box(6, 2, 2, (3.0, 0.5, 0.5))
    body = ElasticBody(mesh.points, mesh.cells, Corotational(mu, 0.0, 1.0))
    clamp = np.flatnonzero(mesh.points[:, 0] < 1e-12)
    rng = np.random.default_rng(3)
    v0 = 0.5 * rng.standard_normal(mesh.points.shape)
    v0[clamp] = 0.0
    return elastic_system(body, pinned=clamp, v0=v0, forces=[Gravity(9.81)])


def _step(system, name: str, state=None, **options):
    integ = get_integrator(name, **options)
    ctx = StepContext()
    st = integ.start(system, system.x0, system.v0, 0.0, H, ctx) if state is None else state
    return integ.step(system, st, H, ctx), ctx


def _newton(system, state=None):
    return _step(system, "newton", state, tol=1e-14, max_iterations=200)[0]


def _objective(system, x, state):
    """``1/(2 h^2) ||x - y||_M^2 + E_arap(x) - f_g . x`` (the implicit-Euler objective)."""
    y = state.x + H * state.v
    d = (x - y)[~system.pinned]
    body = system.forces[0].body
    return (0.5 / H**2 * np.sum(system.mass[~system.pinned, None] * d * d) + body.energy(x)
            - np.sum(system.constant_force() * x))


def test_fixed_point_is_the_newton_solution_of_implicit_euler():
    system = _scene()
    xs = []
    state = None
    for _ in range(2):                                   # two steps: the second from a moving state
        ref = _newton(system, state)
        pd, ctx = _step(system, "projective", state, iterations=5000, tol=1e-14)
        scale = np.abs(ref.x - (system.x0 if state is None else state.x)).max()
        assert scale > 1e-2                              # a real deformation
        assert np.abs(pd.x - ref.x).max() <= 1e-8 * scale
        assert ctx.stats["projective_residual"][-1] <= 1e-14
        xs.append(pd.x)
        state = ref
    assert ctx.stats["projective_iterations"][-1] < 5000


def test_error_falls_linearly_with_the_iteration_count():
    """Past a transient (the stiffer modes converge first) the error is ``C rho^k``: the fitted
    factor explains log(error) (R^2 >= 0.999) and equals the contraction of successive
    iterate differences, the spectral radius of the iteration at its fixed point (linear
    convergence; measured rho ~0.82 here)."""
    system = _scene()
    ref = _newton(system).x
    ks = np.arange(25, 61, 5)
    x = {int(k): _step(system, "projective", iterations=int(k))[0].x for k in [*ks, 59, 61]}
    err = np.array([np.abs(x[int(k)] - ref).max() for k in ks])
    slope, icpt = np.polyfit(ks, np.log(err), 1)
    rho = float(np.exp(slope))
    fit = icpt + slope * ks
    r2 = 1.0 - np.sum((np.log(err) - fit) ** 2) / np.sum((np.log(err) - np.log(err).mean()) ** 2)
    contraction = np.linalg.norm(x[61] - x[60]) / np.linalg.norm(x[60] - x[59])
    assert 0.0 < rho < 1.0
    assert r2 >= 0.999
    assert rho == pytest.approx(contraction, rel=0.03)
    assert np.all(np.diff(err) < 0)


def test_each_sweep_decreases_the_implicit_euler_objective():
    system = _scene()
    integ = get_integrator("projective")
    ctx = StepContext()
    st = integ.start(system, system.x0, system.v0, 0.0, H, ctx)
    g = [_objective(system, get_integrator("projective", iterations=k).step(
        system, st, H, StepContext()).x, st) for k in range(1, 12)]
    assert np.all(np.diff(g) <= 1e-12 * abs(g[0]))


@pytest.mark.parametrize("J", [0.6, 1.5], ids=["compressed", "stretched"])
def test_volume_band_projection_is_the_nearest_point_of_the_band(J, rng=np.random.default_rng(4)):
    from femkit.dynamics.integrators.projective_local import local_step

    pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    body = ElasticBody(pts, [[0, 1, 2, 3]], Corotational(1.0, 0.0))
    Q1, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    Q2, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    s = np.array([1.3, 0.9, 1.0])
    s *= (J / s.prod()) ** (1 / 3)
    F = Q1 @ np.diag(s) @ Q2.T * np.sign(np.linalg.det(Q1 @ Q2.T))
    x = pts @ F.T
    G = body.rest.gradients[0]                            # (4, 3)
    out = np.zeros((4, 3))
    jmin, jmax = 0.9, 1.1
    local = local_step(x, body.rest.cells, body.rest.gradients, np.zeros(1), np.ones(1),
                       jmin, jmax, out)
    B = np.linalg.lstsq(G, out, rcond=None)[0].T          # out = G B^T
    Jb = np.linalg.det(B)
    assert Jb == pytest.approx(jmin if J < jmin else jmax, rel=1e-12)
    # optimality (KKT): F - B is parallel to the gradient of det at B, cof(B) = det(B) B^-T
    D, C = F - B, Jb * np.linalg.inv(B).T
    t = np.sum(D * C) / np.sum(C * C)
    np.testing.assert_allclose(D, t * C, atol=1e-10)
    assert local == pytest.approx(0.5 * np.sum(D * D) * body.rest.volumes[0] / body.rest.volumes[0],
                                  rel=1e-10)


def test_volume_band_keeps_volume_closer():
    changes = []
    for stiffness in (0.0, 2000.0):
        system = _scene(mu=5.0)
        integ = get_integrator("projective", iterations=30, volume_stiffness=stiffness,
                               volume_min=0.99, volume_max=1.01)
        ctx = StepContext()
        st = integ.start(system, system.x0, system.v0 * 4, 0.0, H, ctx)
        worst = 0.0
        for _ in range(10):
            st = integ.step(system, st, H, ctx)
            J = np.linalg.det(system.forces[0].body.deformation_gradients(st.x))
            worst = max(worst, float(np.abs(J - 1.0).max()))
        changes.append(worst)
    assert changes[1] < 0.5 * changes[0]


def test_run_record_and_bad_input():
    system = _scene()
    _, ctx = _step(system, "projective", iterations=7)
    assert ctx.stats["projective_iterations"] == [7]
    assert ctx.stats["projective_residual"][0] > 0 and ctx.stats["projective_local"][0] > 0
    assert ctx.stats["factorizations"] == 1
    with pytest.raises(InputError, match="volume_min"):
        get_integrator("projective", volume_min=1.2)
    from femkit.dynamics.system import MassSpringSystem

    springs = MassSpringSystem(np.array([[0.0, 0], [1, 0]]), np.ones(2), np.array([[0, 1]]), 1.0)
    with pytest.raises(InputError, match="exactly one elastic solid"):
        _step(springs, "projective")


def test_run_summary_keeps_the_residuals_as_numbers():
    from femkit.dynamics.simulate import simulate

    tr = simulate(_scene(), "projective", H, 3 * H, iterations=5)
    stats = tr.summary()["stats"]
    assert stats["projective_iterations"] == {"total": 15, "max": 5}
    res = stats["projective_residual"]
    assert 0.0 < res["last"] <= res["max"] < 1.0
