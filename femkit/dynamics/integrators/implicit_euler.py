"""Implicit Euler, Baraff-Witkin style: one linearised backward-Euler step (SOFA's EulerImplicit).

With ``K = -df/dx`` (femkit's ``stiffness_matrix``), ``D = -df/dv`` (dashpots, viscous) and
Rayleigh coefficients ``(r_M, r_K)``, one linear solve per step::

    ((1 + h r_M) M + h (h + r_K) K + h D) dv = h (f - (h + r_K) K v - r_M M v)
    v+ = v + dv,   x+ = x + h v+

``f`` is every declared force except the Rayleigh term (built into the matrix). This is SOFA's
``((1 + h rM) M - h (h + rK) K_sofa) dv = h (f + (h + rK) K_sofa v - rM M v)`` with
``K_sofa = df/dx = -K``. The system is restricted to the free dofs and solved with the linear
solver named in the step context (``direct``, ``cg``, ``pcg``, ``jacobi``).

First order; unconditionally stable on the linear oscillator (amplitude ``1/sqrt(1 + h^2 w^2)``
per step), i.e. artificially damped. Option ``fix`` (``None``, ``"clamp"``, ``"regularize"``)
makes ``K`` positive semi-definite for CG-type solvers when springs are compressed.

With the ``direct`` (or ``cholesky``) solver and ``reuse_factorization=True`` (opt-in; the default
``False`` factorises every linear system, so ``direct`` means a direct solve) the factorisation of an
earlier step's matrix is kept (when it is SPD) and later steps solve by PCG preconditioned with
it, to ``ctx.linear_solver.rtol`` on the true residual, renewing the factor when a PCG solve costs more than
the average per solve since the factorisation (:meth:`~femkit.solvers.session.LinearSession.solve`): the same step to
that tolerance at a fraction of the cost while the matrix changes slowly. ``reuse_factorization=False``: one factorisation per step.

``matrix_free=True`` (matrix-free CG: Baraff & Witkin 1998; Saad 2003, section 6.7) solves the same system without assembling
it: a ``LinearOperator`` on the free dofs applies
``A d = (1 + h r_M) M d + h (h + r_K) K d + h D d`` through ``system.stiffness_operator`` /
``system.damping_operator`` (spring geometry computed once per step, two sparse passes over
the springs per product), and the right-hand side uses the product ``K v``. It needs
``cg`` or ``pcg`` with ``none``/``jacobi`` (the Jacobi diagonal comes from the spring blocks'
diagonals, :meth:`~femkit.dynamics.system.MassSpringSystem.stiffness_diagonal`); any other
solver raises :class:`~femkit.errors.InputError` when the run starts
(:meth:`.base.Integrator.start`).

With the ``cholesky`` solver the step is compiled: one pass over the springs writes the matrix
values into the free-dof pattern cached for the run and, in the same pass, the spring forces and
``K v`` (:mod:`femkit.dynamics.kernels`); CHOLMOD refactorises on the symbolic analysis of the
first step. Without a definiteness fix a compressed cloth makes the matrix indefinite: that
raises :class:`~femkit.errors.NotSPDError` (use ``fix="clamp"``, or ``direct``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...solvers.operators import free_operator, restrict
from .base import Integrator, StepContext, StepperState, check_matrix_free_options
from .registry import register


@register("implicit_euler")
@dataclass(frozen=True)
class ImplicitEuler(Integrator):
    fix: str | None = None
    reuse_factorization: bool = False
    matrix_free: bool = False

    order = 1
    implicit = True
    symplectic = False
    work_precision = {"baraff_witkin": ("Baraff-Witkin", None, {"fix": "clamp"})}

    def __post_init__(self):
        check_matrix_free_options(self.name, self.matrix_free, self.reuse_factorization)

    def operator(self, system, x, dt: float):
        """``(op, diagonal, K)``: this step's matrix on the free dofs as a ``LinearOperator``
        (never assembled), its diagonal (Jacobi) and the ``d -> K d`` product at ``x``."""
        h = dt
        rm, rk = system.rayleigh
        m = np.repeat(system.mass, system.dim)
        K = system.stiffness_operator(x, fix=self.fix)
        D = system.damping_operator(x)
        a_m, a_k = 1.0 + h * rm, h * (h + rk)

        def product(e):
            return a_m * m * e + a_k * K(e).reshape(-1) + h * D(e).reshape(-1)

        free = system.free_dofs
        diag = a_m * m + a_k * system.stiffness_diagonal(x, fix=self.fix) \
            + h * system.damping_diagonal(x)
        return free_operator(product, free, system.ndof), diag[free], K

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        rm, rk = system.rayleigh
        x, v = state.x, state.v
        free = system.free_dofs
        vf = v.reshape(-1)
        f = system.force(x, v, state.t, rayleigh=False).reshape(-1)
        if self.matrix_free:
            op, diag, Kop = self.operator(system, x, h)
            m = np.repeat(system.mass, system.dim)
            b = h * (f - (h + rk) * Kop(vf).reshape(-1) - rm * m * vf)
            dv = ctx.session.solve(op, b[free], diagonal=diag)
            return self._advance(state, vf, free, dv, h)
        if ctx.session.factors_on_pattern:
            return self._step_compiled(system, state, h, ctx)
        K = system.stiffness_matrix(x, fix=self.fix)
        M = system.mass_matrix()
        A = (1.0 + h * rm) * M + (h * (h + rk)) * K
        D = system.damping_matrix(x)
        if D.nnz:
            A = A + h * D
        b = h * (f - (h + rk) * (K @ vf) - rm * (M @ vf))
        dv = ctx.session.solve(restrict(A, free), b[free], refactor=True,
                               keep="implicit_euler_factor" if self.reuse_factorization else None)
        return self._advance(state, vf, free, dv, h)

    def _step_compiled(self, system, state: StepperState, h: float, ctx: StepContext) -> StepperState:
        """The same step with ``cholesky``: matrix values, spring forces and ``K v`` from one
        compiled pass into the cached free-dof pattern, then a Cholesky refactorisation on the
        kept symbolic analysis (:meth:`femkit.solvers.session.LinearSession.solve_on_pattern`)."""
        from ..kernels.assembly import assemble_with_forces, free_pattern

        rm, rk = system.rayleigh
        x, v = state.x, state.v
        m = np.repeat(system.mass, system.dim)
        a_k = h * (h + rk)
        pat = free_pattern(system, ctx.cache)
        data, f, kv = assemble_with_forces(pat, system, x, v, state.t, diagonal=(1.0 + h * rm) * m,
                                           kcoef=a_k, dcoef=h, fix=self.fix)
        vf = v.reshape(-1)
        b = h * (f.reshape(-1) - (h + rk) * kv.reshape(-1) - rm * m * vf)
        dv = ctx.session.solve_on_pattern(pat.matrix(data), b[pat.free], pat,
                                          "implicit_euler_factor" if self.reuse_factorization else None)
        return self._advance(state, vf, pat.free, dv, h)

    @staticmethod
    def _advance(state: StepperState, vf, free, dv, h: float) -> StepperState:
        v_new = vf.copy()
        v_new[free] += dv
        v_new = v_new.reshape(state.v.shape)
        return StepperState(state.x + h * v_new, v_new, state.t + h)

    def dahlquist_amplification(self, z: complex) -> complex:
        return 1.0 / (1.0 - z)
