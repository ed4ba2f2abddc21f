"""The variational symplectic integrator of ``M u'' + K u = F``: the discrete Euler-Lagrange
equations of the midpoint discrete Lagrangian (Marsden & West 2001, "Discrete mechanics and
variational integrators", Acta Numerica 10; Kharevych et al. 2006), i.e. the implicit
midpoint rule::

    u1 = u + dt (v + v1) / 2,   M (v1 - v) / dt = F(t + dt/2) - K (u + u1) / 2
    =>  (M + dt^2/4 K) u1 = M (u + dt v) - dt^2/4 K u + dt^2/2 F(t + dt/2),  v1 = 2 (u1 - u)/dt - v

One kept factor of ``M + dt^2/4 K``. Second order, symplectic, unconditionally stable; on a
linear system without load it gives the same states as Newmark's average acceleration (the
load enters at the midpoint instead of as the average of the end points).
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import MolState, WaveScheme
from .registry import register_wave


@register_wave("variational_symplectic")
@dataclass(frozen=True)
class VariationalSymplectic(WaveScheme):
    """Implicit midpoint (a variational integrator): second order, symplectic."""

    order = 2

    def step(self, system, state: MolState, dt: float) -> MolState:
        q = 0.25 * dt * dt
        t1 = state.t + dt
        rhs = system.M_f @ (state.u + dt * state.v) - q * (system.K_f @ state.u)
        if system.has_load:
            rhs += 2.0 * q * system.F(state.t + 0.5 * dt)[system.free]
        u1 = system.solve(1.0, q, rhs, t1)
        return MolState(t1, u1, 2.0 * (u1 - state.u) / dt - state.v, None)
