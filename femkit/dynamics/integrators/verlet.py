"""Position (Stormer) Verlet: ``x_{n+1} = 2 x_n - x_{n-1} + h^2 a(x_n)``.

The first step is the Taylor step ``x_1 = x_0 + h v_0 + h^2/2 a_0``. Velocities are never needed
by the recurrence; ``state.v`` reports the second-order estimate
``v_{n+1} = (x_{n+1} - x_n) / h + h/2 a_{n+1}`` (exactly velocity Verlet's velocity in exact
arithmetic), which is also what velocity-dependent forces see (with dashpots, viscous or
Rayleigh damping the method is then only first order). Second order, symplectic,
time reversible; stable for ``h omega < 2``. The closing half kick is the shared
:mod:`.kick_drift_kick` core.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import StepContext, StepperState
from .kick_drift_kick import KickDriftKick
from .registry import register


@register("verlet")
@dataclass(frozen=True)
class Verlet(KickDriftKick):

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["x_prev"] = None
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        x, a, x_prev = state.x, state.aux["a"], state.aux["x_prev"]
        if x_prev is None:
            x_new = x + dt * state.v + (0.5 * dt * dt) * a
        else:
            x_new = 2.0 * x - x_prev + (dt * dt) * a
        v_drift = (x_new - x) / dt
        a_new, v_new = self.kick(system, x_new, v_drift, v_drift, state.t + dt, dt)
        return StepperState(x_new, v_new, state.t + dt, {"a": a_new, "x_prev": x})
