"""Implicit Euler for ``M u'' + K u = F`` (as a first-order system in ``u, v``)::

    (M + dt^2 K) u1 = M (u + dt v) + dt^2 F(t1),   v1 = (u1 - u) / dt

First order and dissipative (each mode's amplitude shrinks by ``1 / sqrt(1 + dt^2 omega^2)``
per step): the comparison for the energy-conserving schemes. One kept factor of ``M + dt^2 K``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import MolState, WaveScheme
from .registry import register_wave


@register_wave("implicit_euler")
@dataclass(frozen=True)
class ImplicitEulerWave(WaveScheme):
    """Backward Euler on ``(u, v)``: first order, unconditionally stable, dissipative."""

    order = 1

    def step(self, system, state: MolState, dt: float) -> MolState:
        t1 = state.t + dt
        rhs = system.M_f @ (state.u + dt * state.v)
        if system.has_load:
            rhs += dt * dt * system.F(t1)[system.free]
        u1 = system.solve(1.0, dt * dt, rhs, t1)
        return MolState(t1, u1, (u1 - state.u) / dt, None)
