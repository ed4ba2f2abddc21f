"""Small systems shared by the integrator tests (SOFA's one-spring scene, a unit oscillator)."""

from __future__ import annotations

import numpy as np

from femkit.dynamics.forces import Gravity, RayleighDamping
from femkit.dynamics.integrators import StepContext
from femkit.dynamics.system import MassSpringSystem


def sofa_spring(K=100.0, m=10.0, g=10.0, rm=0.0, rk=0.0):
    """SOFA's ODE-solver test scene: fixed node at y = 2, rest length 1, mass at y = 1, gravity -g.

    With ``g = K/m`` the free node follows ``y(t) = cos(sqrt(K/m) t)`` exactly.
    """
    forces = [Gravity(g)]
    if rm or rk:
        forces.append(RayleighDamping(rm, rk))
    return MassSpringSystem(np.array([[0.0, 2.0], [0.0, 1.0]]), m, [[0, 1]], K, rest=1.0,
                            pinned=[0], forces=forces)


def unit_oscillator(omega=1.0, amplitude=1.0, rest=100.0):
    """``u'' = -omega^2 u`` for the free node's displacement ``u`` along x (no gravity); u(0) = amplitude.

    The spring (unit mass, ``k = omega^2``) lies along x with a long rest length, so it stays
    linear (length > 0) for displacements smaller than ``rest``.
    """
    sys = MassSpringSystem(np.array([[0.0, 0.0], [rest, 0.0]]), 1.0, [[0, 1]], omega ** 2,
                           rest=rest, pinned=[0])
    x0 = sys.x0.copy()
    x0[1, 0] += amplitude
    return sys, x0


def run(integrator, system, x0, v0, dt, steps, ctx=None):
    """Positions and velocities of the free node 1 at every step (including the start)."""
    ctx = ctx or StepContext()
    state = integrator.start(system, x0, v0, 0.0, dt, ctx)
    xs, vs = [state.x[1].copy()], [state.v[1].copy()]
    for _ in range(steps):
        state = integrator.step(system, state, dt, ctx)
        xs.append(state.x[1].copy())
        vs.append(state.v[1].copy())
    return np.array(xs), np.array(vs), ctx


def damped_particles(gamma):
    """Two free unit-mass particles joined by a k = 0 spring, viscous damping ``a = -gamma v``.

    The velocity obeys Dahlquist's ``v' = lambda v`` with ``lambda = -gamma``, so one step of any
    integrator multiplies ``v`` by its amplification factor ``R(-h gamma)``.
    """
    from femkit.dynamics.forces import ViscousDamping

    return MassSpringSystem(np.array([[0.0, 0.0], [1.0, 0.0]]), 1.0, [[0, 1]], 0.0, rest=1.0,
                            forces=[ViscousDamping(gamma)])


def oscillator_map(integrator, omega, dt):
    """The 2x2 one-step map of ``(u, u')`` of the unit-mass oscillator with frequency ``omega``."""
    system, _ = unit_oscillator(omega, 0.0, rest=1.0)
    cols = []
    eps = 1e-6  # stage values reach ~ (h omega)^4 eps: the spring must keep a positive length
    for u, w in ((eps, 0.0), (0.0, eps)):
        x = system.x0.copy()
        x[1, 0] += u
        v = np.zeros_like(x)
        v[1, 0] = w
        ctx = StepContext()
        s = integrator.step(system, integrator.start(system, x, v, 0.0, dt, ctx), dt, ctx)
        cols.append([(s.x[1, 0] - system.x0[1, 0]) / eps, s.v[1, 0] / eps])
    return np.array(cols).T
