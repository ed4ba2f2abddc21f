"""Symplectic (semi-implicit) Euler, both orderings.

``symplectic_euler`` (velocity first, the usual "semi-implicit Euler" of games and Taichi)::

    v+ = v + h a(x, v);   x+ = x + h v+

``symplectic_euler_position_first``::

    x+ = x + h v;   v+ = v + h a(x+, v)

First order, symplectic; stable on the undamped oscillator for ``h omega < 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import Integrator, StepContext, StepperState
from .registry import register


@register("symplectic_euler")
@dataclass(frozen=True)
class SymplecticEuler(Integrator):
    """Velocity first: kick with the force at the old state, then drift with the new velocity."""

    order = 1
    implicit = False
    symplectic = True
    stability_bound = 2.0

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        v_new = state.v + dt * system.acceleration(state.x, state.v, state.t)
        return StepperState(state.x + dt * v_new, v_new, state.t + dt)


@register("symplectic_euler_position_first")
@dataclass(frozen=True)
class SymplecticEulerPositionFirst(Integrator):
    """Position first: drift with the old velocity, then kick with the force at the new positions."""

    order = 1
    implicit = False
    symplectic = True
    stability_bound = 2.0

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        x_new = state.x + dt * state.v
        v_new = state.v + dt * system.acceleration(x_new, state.v, state.t + dt)
        return StepperState(x_new, v_new, state.t + dt)
