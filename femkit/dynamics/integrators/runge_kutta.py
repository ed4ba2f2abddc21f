"""Explicit Runge-Kutta methods from a Butcher tableau, applied to ``x' = v, v' = a(x, v, t)``.

Explicit Euler, Heun, midpoint (RK2) and RK4 share this one runner; their Dahlquist
amplification ``R(z) = 1 + z b^T (I - z A)^{-1} 1`` comes from the same tableau.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import Integrator, StepContext, StepperState


@dataclass(frozen=True)
class ButcherTableau:
    """Coefficients ``a`` (strictly lower triangular), ``b`` (weights), ``c`` (nodes)."""

    a: tuple
    b: tuple
    c: tuple

    def amplification(self, z: complex) -> complex:
        """Stability function ``R(z) = 1 + z b^T (I - z A)^{-1} 1``."""
        A = np.array(self.a, dtype=complex)
        s = len(self.b)
        k = np.linalg.solve(np.eye(s) - z * A, np.ones(s, dtype=complex))
        return complex(1.0 + z * np.dot(np.array(self.b, dtype=complex), k))


@dataclass(frozen=True)
class ExplicitRungeKutta(Integrator):
    """Explicit RK step on the first-order system ``y = (x, v)``; subclasses set ``tableau``.

    The acceleration includes every declared force (Rayleigh damping too), evaluated at each
    stage state and stage time.
    """

    tableau = ButcherTableau(((0.0,),), (1.0,), (0.0,))
    implicit = False
    symplectic = False

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        tab = self.tableau
        x, v, t, h = state.x, state.v, state.t, dt
        kx: list[np.ndarray] = []
        kv: list[np.ndarray] = []
        for i, ci in enumerate(tab.c):
            X, V = x, v
            for j in range(i):
                aij = tab.a[i][j]
                if aij != 0.0:
                    X = X + (h * aij) * kx[j]
                    V = V + (h * aij) * kv[j]
            kx.append(V)
            kv.append(system.acceleration(X, V, t + ci * h))
        x_new, v_new = x, v
        for bi, kxi, kvi in zip(tab.b, kx, kv):
            if bi != 0.0:
                x_new = x_new + (h * bi) * kxi
                v_new = v_new + (h * bi) * kvi
        return StepperState(x_new, v_new, t + h)

    def dahlquist_amplification(self, z: complex) -> complex:
        return self.tableau.amplification(z)
