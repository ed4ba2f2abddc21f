"""Central difference for ``M u'' + K u = F`` in its velocity form (Newmark with
``beta = 0``, ``gamma = 1/2``)::

    v_h = v + dt/2 a,   u1 = u + dt v_h,   M a1 = F(t1) - K u1,   v1 = v_h + dt/2 a1

Explicit, second order, symplectic; stable for ``dt omega_max <= 2``. A lumped mass makes each
step a division; a consistent mass is factorised once.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import MolState, WaveScheme, acceleration
from .registry import register_wave


@register_wave("central_difference")
@dataclass(frozen=True)
class CentralDifference(WaveScheme):
    """Explicit central difference, second order, stable for ``dt <= 2 / omega_max``."""

    order = 2
    explicit = True
    stability_bound = 2.0

    def step(self, system, state: MolState, dt: float) -> MolState:
        t1 = state.t + dt
        v_h = state.v + 0.5 * dt * state.a
        u1 = state.u + dt * v_h
        u1[system.fixed] = system.g(t1)
        a1 = acceleration(system, u1, t1, dt)
        return MolState(t1, u1, v_h + 0.5 * dt * a1, a1)
