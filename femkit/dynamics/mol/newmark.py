"""Newmark's method for ``M u'' + K u = F`` (Newmark 1959), options ``beta`` and ``gamma``;
the defaults ``1/4, 1/2`` are the average-acceleration (trapezoidal) rule::

    u_p = u + dt v + (1/2 - beta) dt^2 a
    (M + beta dt^2 K) a1 = F(t1) - K u_p,   u1 = u_p + beta dt^2 a1
    v1 = v + dt ((1 - gamma) a + gamma a1)

Solved for the acceleration with one kept factor of ``M + beta dt^2 K``; the Dirichlet nodes
get ``a1 = (g(t1) - u_p) / (beta dt^2)``, so ``u1 = g(t1)`` there. Second order for
``gamma = 1/2``; unconditionally stable for ``2 beta >= gamma >= 1/2``, else for
``dt omega_max <= 1 / sqrt(gamma / 2 - beta)``. The average-acceleration rule conserves
``1/2 v^T M v + 1/2 u^T K u`` exactly without load.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import InputError
from ..integrators.newmark import newmark_stability_bound
from .base import MolState, WaveScheme
from .registry import register_wave


@register_wave("newmark")
@dataclass(frozen=True)
class Newmark(WaveScheme):
    """Newmark's beta-gamma family; average acceleration by default (energy-conserving)."""

    beta: float = 0.25
    gamma: float = 0.5

    @property
    def order(self) -> int:  # type: ignore[override]
        return 2 if self.gamma == 0.5 else 1

    @property
    def stability_bound(self) -> float:  # type: ignore[override]
        return newmark_stability_bound(self.beta, self.gamma)

    def validate(self) -> None:
        if not (self.beta > 0.0 and self.gamma >= 0.5):
            raise InputError(f"integrator 'newmark': need beta > 0 (beta = 0 is "
                             f"central_difference) and gamma >= 1/2, got beta={self.beta!r}, "
                             f"gamma={self.gamma!r}")

    def step(self, system, state: MolState, dt: float) -> MolState:
        b = self.beta * dt * dt
        t1 = state.t + dt
        u_p = state.u + dt * state.v + (0.5 - self.beta) * dt * dt * state.a
        rhs = -(system.K_f @ u_p)
        if system.has_load:
            rhs += system.F(t1)[system.free]
        a1 = system.solve(1.0, b, rhs, t1, values=(system.g(t1) - u_p[system.fixed]) / b)
        u1 = u_p + b * a1
        v1 = state.v + dt * ((1.0 - self.gamma) * state.a + self.gamma * a1)
        return MolState(t1, u1, v1, a1)
