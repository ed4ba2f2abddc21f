"""Leapfrog: velocities live at half steps.

Start ``v_{1/2} = v_0 + h/2 a_0``; then ``x_{n+1} = x_n + h v_{n+1/2}``,
``v_{n+3/2} = v_{n+1/2} + h a(x_{n+1})``. ``state.v`` reports the synchronised
``v_{n+1} = v_{n+1/2} + h/2 a_{n+1}``; the half-step velocity is ``state.aux["v_half"]`` and is
what velocity-dependent forces see. Second order, symplectic; stable for ``h omega < 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import Integrator, StepContext, StepperState
from .registry import INTEGRATORS


@INTEGRATORS.register("leapfrog")
@dataclass(frozen=True)
class Leapfrog(Integrator):
    name = "leapfrog"
    order = 2
    implicit = False
    symplectic = True
    stability_bound = 2.0

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["v_half"] = state.v + (0.5 * dt) * system.acceleration(state.x, state.v, state.t)
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        v_half = state.aux["v_half"]
        x_new = state.x + dt * v_half
        a_new = system.acceleration(x_new, v_half, state.t + dt)
        v_new = v_half + (0.5 * dt) * a_new
        return StepperState(x_new, v_new, state.t + dt, {"v_half": v_half + dt * a_new})
