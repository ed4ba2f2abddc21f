"""Newmark-beta (SOFA's NewmarkImplicitSolver; default ``beta = 1/4, gamma = 1/2``, average acceleration).

Unknown: the new acceleration ``a+`` with::

    x+ = x + h v + h^2 (1/2 - beta) a + h^2 beta a+
    v+ = v + h (1 - gamma) a + h gamma a+
    M a+ = f(x+, v+)            (every declared force, Rayleigh included)

solved by Newton iterations on ``r(a+) = M a+ - f(x+, v+)`` with the Jacobian
``M + h^2 beta K + h gamma (D + r_M M + r_K K)`` (``K``, ``D`` at the current iterate). For linear
forces the first iteration is the exact solution and equals SOFA's closed-form recurrence
``a+ = (F + h cstAcc a + cstVel v) / ((h^2 beta + h gamma r_K) K + (1 + h gamma r_M) M)``; the
loop stops when the residual falls below ``tol`` relative to the force scale (plus the
round-off floor ``100 eps max(k L)`` of the spring forces) or after
``max_iterations`` (then counted in ``ctx.stats["unconverged_steps"]`` with a
:class:`~.base.NonlinearConvergenceWarning` if the residual is still above ``tol`` and the last
correction was not already at round-off of ``a+``). ``state.aux["a"]`` keeps the acceleration of the current state.

Order 2 for ``gamma = 1/2`` (1 otherwise); with ``beta = 1/4, gamma = 1/2`` unconditionally stable
and energy conserving on linear undamped systems (``|R| = 1``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...solvers.operators import restrict
from .base import Integrator, StepContext, StepperState, note_unconverged
from .registry import register


def _roundoff_floor(system) -> float:
    """Round-off level of the residual ``M a - f``: a spring force ``k (l - L)`` carries an
    absolute error of a few ``eps k l``, which a tolerance relative to the *net* force (small
    near equilibrium: a stiff spring with ``k = 1e6`` holding a unit mass) cannot beat."""
    if not system.n_springs:
        return 0.0
    return 100.0 * np.finfo(float).eps * float(np.max(system.k * system.rest))


def newmark_stability_bound(beta: float, gamma: float) -> float:
    """The largest ``h omega`` for which Newmark's method stays bounded on the undamped
    oscillator: ``inf`` for ``2 beta >= gamma >= 1/2``, else ``1 / sqrt(gamma / 2 - beta)``.

    >>> newmark_stability_bound(0.25, 0.5), newmark_stability_bound(0.0, 0.5)
    (inf, 2.0)
    """
    if 2.0 * beta >= gamma >= 0.5:
        return float("inf")
    return float(1.0 / np.sqrt(max(gamma / 2.0 - beta, 1e-300)))


@register("newmark")
@dataclass(frozen=True)
class Newmark(Integrator):
    beta: float = 0.25
    gamma: float = 0.5
    tol: float = 1e-12
    max_iterations: int = 20
    fix: str | None = None

    implicit = True
    symplectic = False

    def __post_init__(self):
        if not (0.0 <= self.beta <= 0.5 and 0.0 <= self.gamma <= 1.0):
            raise InputError(f"newmark: need 0 <= beta <= 1/2 and 0 <= gamma <= 1, "
                             f"got beta={self.beta}, gamma={self.gamma}")
        if self.max_iterations < 1:
            raise InputError("newmark: max_iterations must be >= 1")

    @property
    def order(self) -> int:  # type: ignore[override]
        return 2 if self.gamma == 0.5 else 1

    @property
    def stability_bound(self) -> float:  # type: ignore[override]
        return newmark_stability_bound(self.beta, self.gamma)

    def start(self, system, x, v, t, dt, ctx):
        state = super().start(system, x, v, t, dt, ctx)
        state.aux["a"] = system.acceleration(state.x, state.v, state.t)
        return state

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h, beta, gamma = dt, self.beta, self.gamma
        rm, rk = system.rayleigh
        free = system.free_dofs
        shape = state.x.shape
        M = system.mass_matrix()
        m = M.diagonal()
        a = state.aux["a"].reshape(-1)
        x_pred = state.x.reshape(-1) + h * state.v.reshape(-1) + (h * h * (0.5 - beta)) * a
        v_pred = state.v.reshape(-1) + (h * (1.0 - gamma)) * a
        a_new = a.copy()
        floor = _roundoff_floor(system)
        stalled = False
        iterations = 0
        for iterations in range(1, self.max_iterations + 1):
            x_new = (x_pred + (h * h * beta) * a_new).reshape(shape)
            v_new = (v_pred + (h * gamma) * a_new).reshape(shape)
            f = system.force(x_new, v_new, state.t + h).reshape(-1)
            r = m * a_new - f
            scale = max(np.abs(f[free]).max(initial=0.0), np.abs(m * a_new)[free].max(initial=0.0))
            if iterations > 1 and np.abs(r[free]).max(initial=0.0) <= self.tol * max(scale, 1e-300) + floor:
                break
            K = system.stiffness_matrix(x_new, fix=self.fix)
            J = (1.0 + h * gamma * rm) * M + (h * h * beta + h * gamma * rk) * K
            D = system.damping_matrix(x_new)
            if D.nnz:
                J = J + (h * gamma) * D
            da = ctx.session.solve(restrict(J, free), r[free], refactor=True)
            a_new[free] -= da
            # a correction at round-off of a+ itself: Newton has nothing left to improve
            stalled = np.abs(da).max(initial=0.0) <= 8.0 * np.finfo(float).eps * np.abs(a_new).max(initial=0.0)
        else:
            x_new = (x_pred + (h * h * beta) * a_new).reshape(shape)
            v_new = (v_pred + (h * gamma) * a_new).reshape(shape)
            f = system.force(x_new, v_new, state.t + h).reshape(-1)
            r = np.abs(m * a_new - f)[free].max(initial=0.0)
            scale = max(np.abs(f[free]).max(initial=0.0), np.abs(m * a_new)[free].max(initial=0.0))
            if r > self.tol * max(scale, 1e-300) + floor and not stalled:
                note_unconverged(self.name, ctx, state.t + h, self.max_iterations,
                                 f"residual {r:.3e} > tol x force scale = {self.tol * scale:.3e}")
        ctx.stats.setdefault("newton_iterations", []).append(iterations)
        a_new = a_new.reshape(shape)
        a_new[system.pinned_dofs] = 0.0
        return StepperState(x_new, v_new, state.t + h, {"a": a_new})

    def dahlquist_amplification(self, z: complex) -> complex:
        # Newmark applied to y' = lambda y through y'' = lambda^2 y is not a one-step map of y;
        # for gamma = 1/2 the first-order analogue is the trapezoidal rule.
        if self.gamma != 0.5:
            raise NotImplementedError("only gamma = 1/2 has a first-order (trapezoidal) analogue")
        return (1.0 + z / 2.0) / (1.0 - z / 2.0)
