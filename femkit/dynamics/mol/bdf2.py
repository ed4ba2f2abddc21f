"""BDF2 for ``M u' + K u = F``, with variable steps::

    (a0 M + h K) u_{n+1} = M (-a1 u_n - a2 u_{n-1}) + h F(t_{n+1})

``a0, a1, a2`` of the step ratio ``w = h_n / h_{n-1}``
(:func:`femkit.dynamics.mol.estimate.bdf2_coefficients`; ``3/2, -2, 1/2`` at a constant step:
``(3/2 M + dt K) u2 = M (2 u1 - u0 / 2) + dt F(t2)``). Second order, A-stable (L-stable) at a
constant step, zero-stable for ``w < 1 + sqrt 2`` (the adaptive march changes the step by
halving or doubling it). The first step is one Crank-Nicolson step (second order, so the global
order stays two); every later step of a fixed ``dt`` uses one kept factor of ``3/2 M + dt K``.

Embedded error estimate (``embedded``): Milne's device against the quadratic extrapolation of
the last three states with the variable-step BDF2 error constant
(:func:`femkit.dynamics.mol.estimate.bdf2_constant`, ``2 h^3 / 9`` at a constant step), no
extra solve.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import HeatScheme, MolState
from .estimate import attach_estimate, bdf2_coefficients, bdf2_constant, trapezoid_constant
from .registry import register_heat
from .theta import theta_step


@register_heat("bdf2")
@dataclass(frozen=True)
class BDF2(HeatScheme):
    """Two-step backward differentiation formula, second order, started by Crank-Nicolson."""

    order = 2
    embedded = True

    def step(self, system, state: MolState, dt: float) -> MolState:
        prev = state.aux.get("previous")
        if prev is None:
            new = theta_step(system, state, dt, 0.5)
            c = trapezoid_constant(dt)
        else:
            h_prev = state.aux["dt"]
            a0, a1, a2 = bdf2_coefficients(dt, h_prev)
            t1 = state.t + dt
            rhs = system.M_f @ (-a1 * state.u - a2 * prev)
            if system.has_load:
                rhs += dt * system.F(t1)[system.free]
            new = MolState(t1, system.solve(a0, dt, rhs, t1))
            c = bdf2_constant(dt, h_prev)
        new.aux = {"previous": state.u, "dt": dt}
        return attach_estimate(state, new, c)
