"""Variational symplectic integrator (implicit midpoint; Kharevych et al. 2006, SOFA's
VariationalSymplecticSolver with ``alpha = 1/2``).

With momentum ``p = M v`` and the midpoint ``q* = q_n + h/2 vbar``::

    M vbar = p_n + h/2 F(q*, vbar)          (Newton iterations on q*)
    q_{n+1} = q_n + h vbar = 2 q* - q_n
    p_{n+1} = M vbar + h/2 F(q*, vbar)  =>  v_{n+1} = 2 vbar - v_n

Newton solves ``R(q*) = (4/h^2) M (q* - q_n) - F(q*) - (2/h) p_n = 0`` with the Jacobian
``(4/h^2) M + K + (2/h) (D + r_M M + r_K K)``, starting from ``q* = q_n + h/2 v_n``, until
``||dq||_inf <= tol * L`` or ``max_iterations`` (linear forces: exact after one solve; a step
stopped by ``max_iterations`` is counted in ``ctx.stats["unconverged_steps"]`` with a
:class:`~.base.NonlinearConvergenceWarning`).
``F`` contains every declared force (velocity-dependent ones see ``vbar = 2 (q* - q_n) / h``).

Second order, symplectic, unconditionally stable with ``|R| = 1`` on the linear oscillator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...solvers.operators import restrict
from .base import (Integrator, StepContext, StepperState, box_length, check_iteration_options,
                   note_unconverged)
from .registry import register


@register("variational_symplectic")
@dataclass(frozen=True)
class VariationalSymplectic(Integrator):
    tol: float = 1e-12
    max_iterations: int = 20
    fix: str | None = None

    order = 2
    implicit = True
    symplectic = True

    def __post_init__(self):
        check_iteration_options(self.name, self.max_iterations, self.tol)

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        rm, rk = system.rayleigh
        shape = state.x.shape
        free = system.free_dofs
        qn = state.x.reshape(-1)
        vn = state.v.reshape(-1)
        M = system.mass_matrix()
        m = M.diagonal()
        pn = m * vn
        length = box_length(state.x)
        q = qn + 0.5 * h * vn
        iterations = 0
        for iterations in range(1, self.max_iterations + 1):
            vbar = 2.0 * (q - qn) / h
            F = system.force(q.reshape(shape), vbar.reshape(shape), state.t + 0.5 * h).reshape(-1)
            R = (4.0 / (h * h)) * m * (q - qn) - F - (2.0 / h) * pn
            K = system.stiffness_matrix(q.reshape(shape), fix=self.fix)
            J = (4.0 / (h * h) + 2.0 * rm / h) * M + (1.0 + 2.0 * rk / h) * K
            D = system.damping_matrix(q.reshape(shape))
            if D.nnz:
                J = J + (2.0 / h) * D
            dq = ctx.session.solve(restrict(J, free), -R[free], refactor=True)
            q[free] += dq
            if np.abs(dq).max(initial=0.0) <= self.tol * length:
                break
        else:
            note_unconverged(self.name, ctx, state.t + h, self.max_iterations,
                             f"last correction {np.abs(dq).max(initial=0.0):.3e} > tol * L = "
                             f"{self.tol * length:.3e}")
        ctx.record("newton_iterations", iterations)
        vbar = 2.0 * (q - qn) / h
        x_new = (2.0 * q - qn).reshape(shape)
        v_new = (2.0 * vbar - vn).reshape(shape)
        v_new[system.pinned_dofs] = 0.0
        return StepperState(x_new, v_new, state.t + h)

    def dahlquist_amplification(self, z: complex) -> complex:
        return (1.0 + z / 2.0) / (1.0 - z / 2.0)
