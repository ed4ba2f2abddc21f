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

With the ``direct`` solver and ``reuse_factorization=True`` (opt-in; the default
``False`` factorises every linear system, so ``direct`` means a direct solve) the factorisation of an
earlier step's matrix is kept (when it is SPD) and later steps solve by PCG preconditioned with
it, to ``ctx.rtol`` on the true residual, renewing the factor when a PCG solve costs more than
the average per solve since the factorisation (:func:`.base.solve_linear`): the same step to
that tolerance at a fraction of the cost while the matrix changes slowly. ``reuse_factorization=False``: one factorisation per step.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import Integrator, StepContext, StepperState, restrict, solve_linear
from .registry import INTEGRATORS


@INTEGRATORS.register("implicit_euler")
@dataclass(frozen=True)
class ImplicitEuler(Integrator):
    fix: str | None = None
    reuse_factorization: bool = False

    name = "implicit_euler"
    order = 1
    implicit = True
    symplectic = False

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        rm, rk = system.rayleigh
        x, v = state.x, state.v
        free = system.free_dofs
        vf = v.reshape(-1)
        f = system.force(x, v, state.t, rayleigh=False).reshape(-1)
        K = system.stiffness_matrix(x, fix=self.fix)
        M = system.mass_matrix()
        A = (1.0 + h * rm) * M + (h * (h + rk)) * K
        D = system.damping_matrix(x)
        if D.nnz:
            A = A + h * D
        b = h * (f - (h + rk) * (K @ vf) - rm * (M @ vf))
        dv = solve_linear(restrict(A, free), b[free], ctx, system=system,
                          reuse_key="implicit_euler_factor" if self.reuse_factorization else None)
        v_new = vf.copy()
        v_new[free] += dv
        v_new = v_new.reshape(v.shape)
        return StepperState(x + h * v_new, v_new, state.t + h)

    def dahlquist_amplification(self, z: complex) -> complex:
        return 1.0 / (1.0 - z)
