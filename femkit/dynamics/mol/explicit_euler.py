"""Explicit (forward) Euler for ``M u' + K u = F``: ``M u1 = M u0 - dt (K u0 - F(t0))``.

First order; stable for ``dt * lambda_max <= 2`` (its amplification ``1 - dt lambda`` on each
mode). With a lumped mass each step is a division; a consistent mass is factorised once.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import HeatScheme, MolState
from .registry import register_heat


@register_heat("explicit_euler")
@dataclass(frozen=True)
class ExplicitEuler(HeatScheme):
    """Forward Euler, first order, stable for ``dt <= 2 / lambda_max(M^-1 K)``."""

    order = 1
    explicit = True
    stability_bound = 2.0

    def step(self, system, state: MolState, dt: float) -> MolState:
        u = state.u
        rhs = system.M_f @ u - dt * (system.K_f @ u)
        if system.has_load:
            rhs += dt * system.F(state.t)[system.free]
        t1 = state.t + dt
        return MolState(t1, system.solve(1.0, 0.0, rhs, t1))
