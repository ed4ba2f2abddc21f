"""The theta method for ``M u' + K u = F``: implicit Euler (``theta = 1``) and Crank-Nicolson
(``theta = 1/2``, the default of ``crank_nicolson``, an option)::

    (M + theta dt K) u1 = (M - (1 - theta) dt K) u0 + dt (theta F(t1) + (1 - theta) F(t0))

One factorisation of ``M + theta dt K`` serves every step of a fixed ``dt`` (the right-hand
side matrix is kept too: one SpMV and one pair of triangular solves per step, as in
scikit-fem's heat example ex19). Second order at ``theta = 1/2``, first otherwise;
unconditionally stable for ``theta >= 1/2``, else for ``dt lambda_max <= 2 / (1 - 2 theta)``.

Crank-Nicolson carries an embedded error estimate too (``embedded`` at ``theta = 1/2``): Milne's
device against the quadratic extrapolation of the last three states
(:mod:`femkit.dynamics.mol.estimate`, the trapezoidal rule's ``E = h^3 / 12 u'''``), no extra
solve. Implicit Euler carries an embedded error estimate (``embedded``): the trapezoidal rule with the
same two derivatives, ``u0 + dt/2 (u0' + u1')``, is second order, and its difference from the
implicit Euler value, ``dt/2 (u1' - u0')`` with ``u1' = (u1 - u0) / dt``, estimates the step's
local error at no extra solve (``state.aux["error"]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import InputError
from .base import HeatScheme, MolState
from .estimate import attach_estimate, trapezoid_constant
from .registry import register_heat


def theta_step(system, state: MolState, dt: float, theta: float) -> MolState:
    """One theta-method step of ``dt`` from ``state`` (the factor of ``M + theta dt K`` kept)."""
    u = state.u
    rhs = system.rows(1.0, -(1.0 - theta) * dt) @ u
    if system.has_load:
        t0, t1 = state.t, state.t + dt
        F1 = system.F(t1)[system.free]
        rhs += dt * (theta * F1 + (1.0 - theta) * system.F(t0)[system.free]) if theta != 1.0 \
            else dt * F1
    return MolState(state.t + dt, system.solve(1.0, theta * dt, rhs, state.t + dt))


@register_heat("crank_nicolson")
@dataclass(frozen=True)
class ThetaMethod(HeatScheme):
    """The theta method; ``theta = 1/2`` (Crank-Nicolson) is second order."""

    theta: float = 0.5

    @property
    def embedded(self) -> bool:  # type: ignore[override]
        return self.theta == 0.5

    @property
    def order(self) -> int:  # type: ignore[override]
        return 2 if self.theta == 0.5 else 1

    @property
    def explicit(self) -> bool:  # type: ignore[override]
        return self.theta == 0.0

    @property
    def stability_bound(self) -> float:  # type: ignore[override]
        return math.inf if self.theta >= 0.5 else 2.0 / (1.0 - 2.0 * self.theta)

    def validate(self) -> None:
        if not 0.0 <= self.theta <= 1.0:
            raise InputError(f"integrator {self.name!r}: theta must lie in [0, 1], got {self.theta!r}")

    def step(self, system, state: MolState, dt: float) -> MolState:
        new = theta_step(system, state, dt, self.theta)
        return attach_estimate(state, new, trapezoid_constant(dt)) if self.theta == 0.5 else new


@register_heat("implicit_euler")
@dataclass(frozen=True)
class ImplicitEuler(HeatScheme):
    """Backward Euler: first order, L-stable, with an embedded error estimate."""

    order = 1
    embedded = True

    def step(self, system, state: MolState, dt: float) -> MolState:
        new = theta_step(system, state, dt, 1.0)
        rate = (new.u - state.u) / dt
        old = state.aux.get("rate")
        if old is not None:
            new.aux["error"] = 0.5 * dt * (rate - old)
        new.aux["rate"] = rate
        return new
