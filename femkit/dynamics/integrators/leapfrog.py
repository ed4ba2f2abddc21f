"""Leapfrog: velocities live at half steps.

Start ``v_{1/2} = v_0 + h/2 a_0``; then ``x_{n+1} = x_n + h v_{n+1/2}``,
``v_{n+3/2} = v_{n+1/2} + h a(x_{n+1})``. ``state.v`` reports the synchronised
``v_{n+1} = v_{n+1/2} + h/2 a_{n+1}``; the half-step velocity is ``state.aux["v_half"]`` and is
what velocity-dependent forces see (with damping forces the method is then only first
order). Kick-drift-kick core: :mod:`.kick_drift_kick`. Second order, symplectic; stable for ``h omega < 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import StepContext, StepperState
from .kick_drift_kick import KickDriftKick
from .registry import register


@register("leapfrog")
@dataclass(frozen=True)
class Leapfrog(KickDriftKick):

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["v_half"] = state.v + (0.5 * dt) * state.aux.pop("a")
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        v_half = state.aux["v_half"]
        x_new, a_new, v_new = self.drift_kick(system, state.x, v_half, v_half, state.t + dt, dt)
        return StepperState(x_new, v_new, state.t + dt, {"v_half": v_half + dt * a_new})
