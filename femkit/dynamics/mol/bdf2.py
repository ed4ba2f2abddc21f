"""BDF2 for ``M u' + K u = F``: ``(3/2 M + dt K) u2 = M (2 u1 - u0 / 2) + dt F(t2)``.

Second order, A-stable (L-stable). The first step is one Crank-Nicolson step (second order,
so the global order stays two); every later step of a fixed ``dt`` uses one kept factor of
``3/2 M + dt K``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import HeatScheme, MolState
from .registry import register_heat
from .theta import theta_step


@register_heat("bdf2")
@dataclass(frozen=True)
class BDF2(HeatScheme):
    """Two-step backward differentiation formula, second order, started by Crank-Nicolson."""

    order = 2

    def step(self, system, state: MolState, dt: float) -> MolState:
        prev = state.aux.get("previous")
        if prev is None or state.aux.get("dt") != dt:
            new = theta_step(system, state, dt, 0.5)
        else:
            t1 = state.t + dt
            rhs = system.M_f @ (2.0 * state.u - 0.5 * prev)
            if system.has_load:
                rhs += dt * system.F(t1)[system.free]
            new = MolState(t1, system.solve(1.5, dt, rhs, t1))
        new.aux = {"previous": state.u, "dt": dt}
        return new
