"""Fast mass-spring with declared damping and contact: the local/global iteration must stay an
implicit method (converge to the implicit Euler step) when damping is strong, and warn up front
when a penalty contact is too stiff for its explicit treatment."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.optimize import root

from femkit.dynamics.forces import Gravity, GroundContact, RayleighDamping, ViscousDamping
from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.dynamics.simulate import simulate
from femkit.dynamics.topology import rope
from femkit.errors import StabilityWarning

# h * (damping / mass) well above 1 for every form: the old explicit-in-iteration treatment of
# these forces diverged at once (energy x 1e3 .. 1e8 in the first steps)
DAMPINGS = {
    "viscous": dict(forces=[ViscousDamping(5.0)]),
    "rayleigh-alpha": dict(forces=[RayleighDamping(300.0, 0.0)]),
    "rayleigh-beta": dict(forces=[RayleighDamping(0.0, 0.1)]),
    "dashpot": dict(damping=5.0),
    "all-four": dict(forces=[ViscousDamping(2.0), RayleighDamping(100.0, 0.05)], damping=2.0),
}


def _rope(**kw):
    forces = [Gravity(9.81)] + list(kw.pop("forces", []))
    return rope(5, 1.0, k=50.0, total_mass=0.1, forces=forces, **kw)


def _implicit_euler_reference(system, x, v, h, steps):
    """Backward Euler from its definition, ``M (x+ - x - h v) = h^2 f(x+, (x+ - x)/h)``, solved
    on the free dofs with scipy's root finder (independent of femkit's integrators)."""
    free = ~system.pinned
    m = system.mass[free][:, None]
    for _ in range(steps):
        def residual(z, x=x, v=v):
            xn = x.copy()
            xn[free] = z.reshape(-1, system.dim)
            r = m * (xn[free] - x[free] - h * v[free]) \
                - h * h * system.force(xn, (xn - x) / h)[free]
            return r.ravel()

        sol = root(residual, (x + h * v)[free].ravel(), method="hybr", tol=1e-13)
        scale = np.abs(m * h * v[free]).max() + h * h * np.abs(system.force(x, v)[free]).max()
        assert np.abs(residual(sol.x)).max() <= 1e-12 * scale, sol.message
        x_new = x.copy()
        x_new[free] = sol.x.reshape(-1, system.dim)
        x, v = x_new, (x_new - x) / h
    return x


@pytest.mark.parametrize("kind", list(DAMPINGS), ids=list(DAMPINGS))
def test_converged_fast_mass_spring_is_implicit_euler_with_strong_damping(kind):
    system = _rope(**DAMPINGS[kind])
    v0 = np.zeros_like(system.x0)
    v0[1:, 1] = np.linspace(0.5, 2.0, system.n - 1)  # swing: springs stretch and rotate
    h, steps = 1e-2, 5
    integ = get_integrator("fast_mass_spring", iterations=3000, tol=1e-14)
    ctx = StepContext()
    s = integ.start(system, system.x0, v0, 0.0, h, ctx)
    for _ in range(steps):
        s = integ.step(system, s, h, ctx)
    ref = _implicit_euler_reference(system, system.x0, v0, h, steps)
    disp = np.abs(ref - system.x0).max()
    assert disp > 1e-3
    np.testing.assert_allclose(s.x, ref, rtol=0, atol=1e-8 * disp)


@pytest.mark.parametrize("kind", list(DAMPINGS), ids=list(DAMPINGS))
def test_fast_mass_spring_with_ten_iterations_stays_bounded_under_strong_damping(kind):
    system = _rope(**DAMPINGS[kind])
    tr = simulate(system, "fast_mass_spring", 1e-2, 1.0, iterations=10)
    assert tr.completed
    e = tr.energies["total"]
    assert e.max() <= e[0] + 1e-9 * tr.energy_scale  # damped: energy never rises above start


def test_fast_mass_spring_warns_when_contact_is_too_stiff_for_its_iteration():
    # h^2 k_c / m = 1e-4 * 2e4 / 0.02 = 100 > 1: the contact force, explicit within the
    # local/global iteration, makes it diverge on the first contact
    system = _rope(forces=[GroundContact(2e4, height=-0.05)], pinned="none")
    with pytest.warns(StabilityWarning, match=r"fast_mass_spring.*contact.*newton"):
        get_integrator("fast_mass_spring").start(system, system.x0, system.v0, 0.0, 1e-2,
                                                 StepContext())
    soft = _rope(forces=[GroundContact(10.0, height=-0.05)], pinned="none")
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)
        get_integrator("fast_mass_spring").start(soft, soft.x0, soft.v0, 0.0, 1e-2, StepContext())


# ----------------------------------------------------------------------------- documented orders
def _damped_spring_error(name, dt, alpha, beta):
    """|x(1) - exact| of a unit mass on a k = 100 spring with Rayleigh damping (1-D motion)."""
    import math

    from femkit.dynamics.system import MassSpringSystem

    k, c = 100.0, alpha + beta * 100.0
    s = MassSpringSystem([[0.0, 0.0], [1.2, 0.0]], 1.0, [[0, 1]], k, rest=1.0, pinned=[0],
                         forces=[RayleighDamping(alpha, beta)])
    tr = simulate(s, name, dt, 1.0)
    zeta_w, wd = c / 2.0, math.sqrt(k - c * c / 4.0)   # underdamped closed form, x(0)=0.2, v(0)=0
    exact = 1.0 + 0.2 * math.exp(-zeta_w) * (math.cos(wd) + zeta_w / wd * math.sin(wd))
    return abs(tr.x[-1, 1, 0] - exact)


@pytest.mark.parametrize("name,alpha,beta,order", [
    ("velocity_verlet", 0.5, 0.005, 2), ("newmark", 0.5, 0.005, 2),
    ("verlet", 0.5, 0.0, 1), ("leapfrog", 0.5, 0.0, 1),
    ("central_difference", 0.5, 0.0, 2), ("central_difference", 0.0, 0.005, 1),
], ids=["velocity_verlet", "newmark", "verlet", "leapfrog", "central_difference-rM",
        "central_difference-rK"])
def test_order_with_damping_is_the_documented_one(name, alpha, beta, order):
    ratio = _damped_spring_error(name, 2e-3, alpha, beta) / _damped_spring_error(name, 1e-3, alpha, beta)
    assert ratio == pytest.approx(2.0 ** order, rel=0.1)
