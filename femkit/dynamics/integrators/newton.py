"""Implicit Euler solved exactly (to a tolerance) as a minimisation, by Newton's method.

``x+ = argmin g(x)``, ``g(x) = 1/2 ||x - y||_M^2 + h^2 E(x) + h/2 ||x - x_n||_C^2``, with
``y = x_n + h v_n``, ``E`` the potential energy of every conservative force (springs, gravity,
contact: ``system.potential_energy``; gravity inside ``E`` is the same as Liu et al. 2013's
``y = x_n + h v_n + h^2 M^-1 f_ext``) and ``C = D(x_n) + r_M M + r_K K(x_n)`` the damping
(dashpots, viscous, Rayleigh) frozen at the start of the step (implicit in velocity, exact for
constant damping). Then ``v+ = (x+ - x_n) / h``.

Each iteration solves ``(M + h^2 K_fix(x) + h C) dx = -grad g(x)`` on the free dofs (``K_fix``
with the per-spring eigenvalue clamp ``fix="clamp"`` by default, or ``"regularize"``, so ``dx``
is a descent direction; to the linear solver's ``rtol``, or up to :data:`FORCING` where rounding
keeps ``rtol`` out of reach), then backtracks (Armijo, Nocedal & Wright, Numerical Optimization, section 3.1: ``g(x + t dx) <= g(x) + c t grad.dx``,
``t *= shrink``). It stops when ``||dx||_inf <= tol * L`` (``L`` = bounding-box diagonal of
``x_n``) or after ``max_iterations``; the iteration count of every step is appended to
``ctx.stats["newton_iterations"]``, and a step stopped by ``max_iterations`` is counted in
``ctx.stats["unconverged_steps"]`` with a :class:`~.base.NonlinearConvergenceWarning` at the
first one. Armijo's test allows the round-off level of ``g`` (``64 eps`` times the size of its
terms, an elastic body's ``sum (mu + |lam|) vol`` among them, as
:func:`femkit.solids.solve_static` does), so iterates keep converging where differences of ``g``
drown in rounding. A line search that still finds no decrease takes the full step when it lowers
the residual ``|grad g|`` on the free dofs, and otherwise -- or when ``g`` is not finite -- the
step fails: :class:`~.base.NewtonStepError` with the residual history of the step (a
:class:`~femkit.errors.EquilibriumError`; :func:`~femkit.dynamics.simulate.simulate` attaches
the trajectory so far).

With the ``direct`` (or ``cholesky``) solver and ``reuse_factorization=True`` (opt-in; the default
``False`` factorises every linear system, so ``direct`` means a direct solve) the factorisation of an
earlier Newton matrix (this step's or a previous step's) is kept and later Newton systems are
solved by PCG preconditioned with it, to the same relative residual ``ctx.linear_solver.rtol`` on the true
residual; the factor is renewed when a PCG solve costs more than the average cost per solve
since the factorisation (see :meth:`femkit.solvers.session.LinearSession.solve`; ``ctx.stats``: ``factorizations``,
``refactorizations``, ``linear_iterations``, ``time_pcg``).
Each Newton direction is the same to that tolerance, so the iterates are those of Newton with
exact solves; only the cost changes (one factorisation typically serves several steps).

``matrix_free=True`` assembles nothing: ``C`` is applied as the product
``D(x_n) e + r_M M e + r_K K(x_n) e`` (``system.damping_operator``/``stiffness_operator``) in
``g``, its gradient and the Newton operator ``M + h^2 K_fix(x) + h C``, a ``LinearOperator`` on
the free dofs solved by ``cg`` or ``pcg`` with ``none``/``jacobi`` (diagonal from the spring
blocks, :meth:`~femkit.dynamics.system.MassSpringSystem.stiffness_diagonal`); other solvers
raise :class:`~femkit.errors.InputError` when the run starts. The iterates are those of the
assembled path to the linear solver's tolerance.

With the ``cholesky`` solver each Newton matrix is written by one compiled pass over the springs
into the free-dof pattern cached for the run (the clamp applied in the same pass; ``C`` assembled
once per step on the same pattern) and refactorised by CHOLMOD on the symbolic analysis of the
first iteration (:meth:`femkit.solvers.session.LinearSession.solve_on_pattern`).

Barrier contact (:class:`~femkit.dynamics.forces.BarrierContact`, IPC: Li et al. 2020): a
system with a force that ``requires_bounded_steps`` is run the IPC way -- after the forces'
``begin_step`` (the barrier stiffness, lagged friction, moving obstacles moved as far as CCD
allows) each step starts from ``x_n`` moved towards the inertial prediction ``y`` as far as CCD
allows, when that lowers the objective (``y`` itself may lie past a contact), else from ``x_n``;
every line search starts from ``t_max = min(1, step_bound)``, the
collision-free step size of CCD, so no iterate ever crosses a surface; a full step along which
the objective still falls almost linearly (a fold collapsing, which the clamped spring Hessian
sees far too stiff) is extended to the minimum of the quadratic through the objective's value,
slope and value at the full step, at most 8 steps and bounded by CCD again; after each iteration
``end_iteration`` may raise the barrier stiffness (the objective is then re-evaluated);
convergence is judged on the Newton direction ``||dx||_inf`` (a short CCD-bounded step is no
sign of convergence); and the step is solved again while ``advance`` moves a prescribed-motion
obstacle on towards its place at the step's end (carrying the bodies touching it: ``advance``
writes the iterate in place), then while ``relag`` asks for another friction
lagging iteration. ``keeps_contact = True`` declares it (the trait the other integrators lack). A contact Hessian
couples any two surface nodes, outside the compiled pattern of the ``cholesky`` path: there the
springs (and any other force) are written by the compiled pass and the contact Hessian is added on
the run's :class:`~femkit.dynamics.kernels.assembly.ContactPattern` (the compiled pattern joined to
the blocks of the node pairs in contact), rebuilt only when a new pair couples outside it -- so the
factorisation is refactorised in place on one symbolic analysis for most iterations; with
``direct`` (or Rayleigh's ``r_K`` with contact) the Newton matrix is assembled generally.

First order; unconditionally stable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError, SolverError
from ...solvers.operators import free_operator, restrict
from .base import (Integrator, NewtonStepError, StepContext, StepperState, box_length,
                   check_iteration_options, check_matrix_free_options, note_unconverged)
from .registry import register


@register("newton")
@dataclass(frozen=True)
class NewtonImplicitEuler(Integrator):
    tol: float = 1e-10
    max_iterations: int = 50
    fix: str | None = "clamp"
    armijo: float = 1e-4
    shrink: float = 0.5
    max_backtracks: int = 40
    reuse_factorization: bool = False
    matrix_free: bool = False

    order = 1
    implicit = True
    symplectic = False
    keeps_contact = True    # every line-search step bounded by the forces' step_bound (CCD)
    solves_per_step = 4.0   # ~4 Newton iterations measured on the springs_vs_elements scenes
    #: stopped by the iteration count, not the tolerance
    work_precision = {"newton": ("Newton", "max_iterations", {"tol": 1e-14})}

    def __post_init__(self):
        check_iteration_options(self.name, self.max_iterations, self.tol)
        if not (0.0 < self.armijo < 0.5 and 0.0 < self.shrink < 1.0):
            raise InputError("newton: need 0 < armijo < 1/2 and 0 < shrink < 1")
        check_matrix_free_options(self.name, self.matrix_free, self.reuse_factorization)

    def damping_operator(self, system, xn):
        """``(e -> C e, diag C)``, flat vectors, of the step's frozen damping
        ``C = D(x_n) + r_M M + r_K K(x_n)`` without assembling it (``matrix_free=True``)."""
        rm, rk = system.rayleigh
        m = np.repeat(system.mass, system.dim)
        D = system.damping_operator(xn)
        K = system.stiffness_operator(xn) if rk != 0.0 else None
        diag = system.damping_diagonal(xn) + rm * m
        if K is not None:
            diag = diag + rk * system.stiffness_diagonal(xn)

        def product(e):
            out = D(e).reshape(-1) + rm * m * e
            if K is not None:
                out += rk * K(e).reshape(-1)
            return out

        return product, diag

    def newton_operator(self, system, x, h: float, C):
        """``(op, diag)``: ``M + h^2 K_fix(x) + h C`` on the free dofs as a ``LinearOperator``
        (never assembled) and its diagonal; ``C = (product, diagonal)`` from
        :meth:`damping_operator`."""
        m = np.repeat(system.mass, system.dim)
        K = system.stiffness_operator(x, fix=self.fix)
        c_apply, c_diag = C

        def product(e):
            return m * e + (h * h) * K(e).reshape(-1) + h * c_apply(e)

        free = system.free_dofs
        diag = m + (h * h) * system.stiffness_diagonal(x, fix=self.fix) + h * c_diag
        return free_operator(product, free, system.ndof), diag[free]

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        h = dt
        rm, rk = system.rayleigh
        shape = state.x.shape
        free = system.free_dofs
        xn = state.x.reshape(-1)
        M = system.mass_matrix()
        m = M.diagonal()
        forces = system.forces
        contact = [f for f in forces if f.requires_bounded_steps]
        bounded = bool(contact)
        # the compiled pattern holds the springs' and nodal blocks; a contact Hessian, which
        # couples any two surface nodes, goes on the run's ContactPattern (that pattern joined
        # to the contact pairs' blocks); Rayleigh damping's K(x_n) with contact assembles
        # generally
        compiled = ctx.session.factors_on_pattern and not self.matrix_free and not (
            bounded and rk != 0.0)
        if self.matrix_free:
            C = self.damping_operator(system, state.x)
            c_apply = C[0]
        elif compiled:  # C on the cached pattern, the springs in one compiled pass
            from ..kernels.assembly import assemble_with_forces, contact_values, free_pattern

            pat = free_pattern(system, ctx.cache)
            zero_v = np.zeros(shape)
            damped = rm or rk or system._has_dashpots or any(
                f.damping(state.x) is not None for f in system.forces)
            if damped:
                c_data = assemble_with_forces(pat, system, state.x, zero_v, state.t,
                                              diagonal=rm * m, kcoef=rk, dcoef=1.0, fix=None,
                                              skip=contact)[0]
                Cf = pat.matrix(c_data)

                def c_apply(e):
                    out = np.zeros_like(e)
                    out[free] = Cf @ e[free]
                    return out
            else:  # nothing damps: C = 0
                c_data = 0.0

                def c_apply(e):
                    return np.zeros_like(e)
        else:
            C = system.damping_matrix(state.x)
            if rm != 0.0:
                C = C + rm * M
            if rk != 0.0:
                C = C + rk * system.stiffness_matrix(state.x)
            c_apply = C.__matmul__
        y = xn + h * state.v.reshape(-1)
        length = box_length(state.x)

        stored = sum(float(getattr(f, "stored_scale", 0.0)) for f in system.forces)

        def g(xf):
            """The objective and its round-off level (64 eps times the size of its terms)."""
            d, e = xf - y, xf - xn
            try:
                en = system.energies(xf.reshape(shape), None)
            except SolverError:           # an element pass that is not finite there
                return np.inf, 0.0
            inertia, damping = 0.5 * d @ (m * d), 0.5 * h * (e @ c_apply(e))
            value = inertia + h * h * (en["spring"] + en["gravity"] + en["contact"]) + damping
            size = abs(inertia) + abs(damping) + h * h * (
                abs(en["spring"]) + abs(en["gravity"]) + abs(en["contact"]) + stored)
            return value, _ROUNDOFF * size

        def gradient(xf):
            return m * (xf - y) + h * h * system.potential_gradient(xf.reshape(shape)).reshape(-1) \
                + h * c_apply(xf - xn)

        x = y.copy()
        x[~_free_mask(free, xn.size)] = xn[~_free_mask(free, xn.size)]
        if bounded:  # start where the step began: y may lie past a contact
            for f in forces:
                f.begin_step(state.x, h, gradient, t=state.t)
            x, gx, noise = self._warm_start(g, forces, shape, xn, x)
        else:
            gx, noise = g(x)
        residuals = []
        iterations = 0
        while True:  # once, or once per friction lagging iteration
            for it in range(1, self.max_iterations + 1):
                iterations += 1
                if compiled:  # the matrix first: an elastic body's element pass then serves the gradient
                    data = assemble_with_forces(pat, system, x.reshape(shape), zero_v, state.t,
                                                diagonal=m, kcoef=h * h, dcoef=0.0, fix=self.fix,
                                                skip=contact)[0]
                    data += h * c_data
                    on = pat
                    if contact:
                        on, data = contact_values(pat, data, [
                            f.stiffness(x.reshape(shape), "clamp" if self.fix == "clamp" else None)
                            for f in contact], h * h, ctx.cache)
                grad = gradient(x)
                residuals.append(float(np.linalg.norm(grad[free])))
                dx = np.zeros_like(x)
                if self.matrix_free:
                    op, diag = self.newton_operator(system, x.reshape(shape), h, C)
                    dx[free] = ctx.session.solve(op, -grad[free], diagonal=diag,
                                                 accept=FORCING)
                elif compiled:
                    dx[free] = ctx.session.solve_on_pattern(
                        on.matrix(data), -grad[free], on,
                        "newton_factor" if self.reuse_factorization else None, accept=FORCING)
                else:
                    H = M + (h * h) * system.stiffness_matrix(x.reshape(shape), fix=self.fix) + h * C
                    dx[free] = ctx.session.solve(
                        restrict(H, free), -grad[free], refactor=True,
                        keep="newton_factor" if self.reuse_factorization else None,
                        accept=FORCING)
                t_max = min([1.0] + [f.step_bound(x.reshape(shape), (x + dx).reshape(shape))
                                     for f in forces]) if bounded else 1.0
                t, x_try, g_try, noise_try = self._line_search(
                    g, gradient, x, dx, grad, gx, noise, t_max, free, residuals, state, h,
                    iterations)
                if bounded and t >= 1.0:
                    t, x_try, g_try, noise_try = self._extrapolate(
                        g, forces, shape, x, dx, grad[free] @ dx[free], gx, t, x_try, g_try,
                        noise_try)
                # with contact the Newton direction decides (IPC): a CCD-bounded t is no sign
                # of convergence
                step_size = (1.0 if bounded else t) * np.abs(dx).max(initial=0.0)
                x, gx, noise = x_try, g_try, noise_try
                if bounded and any([f.end_iteration(x.reshape(shape)) for f in forces]):
                    gx, noise = g(x)   # the barrier stiffness changed: a new objective
                if step_size <= self.tol * length:
                    converged = True
                    break
            else:
                converged = False
            # moving obstacles first (their place at the step's end), then friction lagging
            if not (bounded and converged and (
                    any([f.advance(x.reshape(shape)) for f in forces])
                    or any([f.relag(state.x, x.reshape(shape), h) for f in forces]))):
                break
            gx, noise = g(x)
        if bounded:
            for f in forces:
                f.end_step()
        ctx.record("newton_iterations", iterations)
        if not converged:
            note_unconverged(self.name, ctx, state.t + h, self.max_iterations,
                             f"last Newton step {step_size:.3e} > tol * L = {self.tol * length:.3e}")
        x_new = x.reshape(shape)
        v_new = ((x - xn) / h).reshape(shape)
        return StepperState(x_new, v_new, state.t + h)

    def _line_search(self, g, gradient, x, dx, grad, gx, noise, t_max, free, residuals, state,
                     h, iterations):
        """Armijo backtracking from ``t_max`` (the forces' step bound, 1 without contact):
        ``(t, x_try, g_try, noise_try)``; :class:`~.base.NewtonStepError` when it fails."""
        slope = grad[free] @ dx[free]
        t = t_max
        if slope < 0.0:
            for _ in range(self.max_backtracks):
                x_try = x + t * dx
                g_try, noise_try = g(x_try)
                if g_try <= gx + self.armijo * t * slope + max(noise, noise_try):
                    break
                t *= self.shrink
            else:  # no decrease above round-off: a full step must lower the residual
                t, x_try = t_max, x + t_max * dx
                g_try, noise_try = g(x_try)
                lower = np.isfinite(g_try) and np.linalg.norm(
                    gradient(x_try)[free]) < (1.0 - self.armijo) * residuals[-1]
                if not lower:
                    self._fail(state, h, iterations, residuals,
                               "the line search found no decrease")
        else:  # not a descent direction (no definiteness fix): take the full Newton step
            x_try = x + t_max * dx
            g_try, noise_try = g(x_try)
        if not np.isfinite(g_try):
            self._fail(state, h, iterations, residuals, "the objective is not finite")
        return t, x_try, g_try, noise_try

    def _warm_start(self, g, forces, shape, xn, y):
        """IPC's start of a contact step: from ``x_n`` towards the inertial prediction ``y``
        (``x_n + h v_n`` on the free dofs) as far as CCD allows, when that lowers the
        objective; else ``x_n``. Returns ``(x, g(x), its round-off level)``."""
        gx, noise = g(xn)
        t = min([1.0] + [f.step_bound(xn.reshape(shape), y.reshape(shape)) for f in forces])
        if t <= 0.0:
            return xn.copy(), gx, noise
        x = xn + t * (y - xn)
        g_try, noise_try = g(x)
        if np.isfinite(g_try) and g_try < gx:
            return x, g_try, noise_try
        return xn.copy(), gx, noise

    def _extrapolate(self, g, forces, shape, x, dx, slope, gx, t, x_try, g_try, noise_try):
        """A full step accepted with the objective still falling almost linearly along ``dx``
        (the decrease at least :data:`EXTRAPOLATE_RATIO` of ``t * slope``: the modified Newton
        matrix, its spring blocks clamped, is far stiffer along ``dx`` than the objective -- a
        fold collapsing) is extended to the minimum of the quadratic through ``g(x)``, the slope
        and ``g(x + dx)``, at most :data:`EXTRAPOLATE_MAX` ``dx`` and bounded by CCD as every
        step is; kept when it lowers the objective further and passes Armijo's test.
        Returns ``(t, x_try, g_try, noise_try)``, the full step's when not extended."""
        if not slope < 0.0 or (g_try - gx) > EXTRAPOLATE_RATIO * t * slope:
            return t, x_try, g_try, noise_try
        curvature = 2.0 * (g_try - gx - t * slope) / (t * t)   # of g(x + s dx) in s
        far = EXTRAPOLATE_MAX if curvature <= 0.0 else min(-slope / curvature, EXTRAPOLATE_MAX)
        far *= min([1.0] + [f.step_bound(x.reshape(shape), (x + far * dx).reshape(shape))
                            for f in forces])
        if far <= t:
            return t, x_try, g_try, noise_try
        x_far = x + far * dx
        g_far, noise_far = g(x_far)
        if np.isfinite(g_far) and g_far < g_try and g_far <= gx + self.armijo * far * slope:
            return far, x_far, g_far, noise_far
        return t, x_try, g_try, noise_try

    def _fail(self, state: StepperState, h: float, iterations: int, residuals: list,
              why: str) -> None:
        raise NewtonStepError(
            f"{self.name}: Newton failed in the step from t = {state.t:.6g} to {state.t + h:.6g} "
            f"at iteration {iterations}: {why} (residuals "
            f"{', '.join(f'{r:.3e}' for r in residuals[-6:])})", state.t + h, residuals,
            state.x.copy())

    def dahlquist_amplification(self, z: complex) -> complex:
        return 1.0 / (1.0 - z)


#: The relative residual a Newton direction is used with when the linear solver's ``rtol`` is out
#: of reach (a stiff barrier's ill-conditioned matrix: rounding alone leaves more): inexact Newton
#: (Dembo, Eisenstat & Steihaug 1982) converges for any forcing term below 1; the line search and
#: the step-size stopping rule judge the iterates (``linear_solver.stats["inexact_solves"]``).
FORCING = 1e-3

#: Armijo's test allows this many ulps of the objective's terms (as the static solver does,
#: :mod:`femkit.solids.static`): near the minimum the objective stops changing above its
#: rounding while the gradient is still far from it.
_ROUNDOFF = 64 * np.finfo(float).eps
#: With contact, a full step whose objective decrease is at least this fraction of the linear
#: model's (a quadratic model's would be 1/2) is extended (:meth:`NewtonImplicitEuler._extrapolate`).
EXTRAPOLATE_RATIO = 0.75
#: ... to at most this many Newton steps.
EXTRAPOLATE_MAX = 8.0


def _free_mask(free: np.ndarray, ndof: int) -> np.ndarray:
    mask = np.zeros(ndof, dtype=bool)
    mask[free] = True
    return mask
