"""Quasi-static equilibrium: ``min_x E(x) - f . x`` with prescribed displacements, by Newton's
method with a backtracking line search and load stepping.

Load step ``k = 1..K`` applies ``k/K`` of the external forces and of the prescribed
displacements, starting from the previous equilibrium. The prescribed increment is not applied
to the held nodes alone (their jump would crush, and with a ``log J`` energy invert, the layer of
elements next to them): it is spread into the body by one linear solve, the linear elastic
response ``H_ff dx_f = -H_fc dx_c`` of the projected tangent at the previous equilibrium to the
increment ``dx_c`` of the held dofs (the increment as Dirichlet data of the linearised problem).
When that start still has an element of non-finite energy, the step's increment is halved (up
to :data:`MAX_CUTS` times) and the step is taken in those sub-steps, each from the equilibrium of
the one before; the record's ``substeps`` says how many.

From that start Newton iterates on the free dofs: ``H_ff dx = -r_f`` with the element-wise
PSD-projected Hessian (Teran et al. 2005; ``project=True`` by default, so ``dx`` is a descent
direction), then Armijo backtracking on the total potential (Nocedal & Wright, Numerical
Optimization, section 3.1), as :mod:`femkit.dynamics.integrators.newton` does for implicit
Euler; a trial point with an element of non-finite energy counts as no decrease. The Armijo
test allows the round-off level of the potential
(``64 eps (|E| + |f.x| + sum (mu + |lam|) vol)``, the last term the size of the terms an energy
density sums before they cancel near rest), and when even that finds no decrease, a full step
that lowers the residual norm is taken: without these Newton stalls where energy differences
drown in rounding while the residual is still ~1e-8 relative. Converged when
``|r_f| <= rtol max(|f_k|, |r_0|)`` (``r_0``: residual at the start of the (sub-)step) or the
step ``|dx|_inf <= xtol L`` (``L`` the bounding-box diagonal).

Failure -- a line search that finds no decrease, the iteration limit, an increment that inverts
elements however cut -- raises :class:`~femkit.errors.EquilibriumError` carrying the record so
far (load steps done, iterations, residual histories) and the last equilibrium.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..errors import EquilibriumError, InputError, SolverError
from ..solvers.core import defaults
from ..solvers.spec import SolverSpec
from .body import ElasticBody
from .boundary import Dirichlet

__all__ = ["StaticResult", "LoadStepRecord", "solve_static"]


@dataclass
class LoadStepRecord:
    """One load step: its factor, Newton iterations, residual norms (one per iterate, the first
    before any step), accepted step lengths ``t`` of the line search, whether it converged and
    (``project="auto"``) how many iterations fell back to the projected Hessian; ``substeps``:
    how many pieces the step was cut into (1: solved whole; see :func:`solve_static`)."""

    load_factor: float
    iterations: int = 0
    residuals: list = field(default_factory=list)
    step_lengths: list = field(default_factory=list)
    converged: bool = False
    projected: int = 0
    substeps: int = 1


@dataclass
class StaticResult:
    """Equilibrium positions ``x`` ``(n, d)``, displacement ``u = x - X``, the per-load-step
    records and totals."""

    x: np.ndarray
    u: np.ndarray
    steps: list
    energy: float

    @property
    def iterations(self) -> int:
        return int(sum(s.iterations for s in self.steps))

    @property
    def converged(self) -> bool:
        return bool(self.steps) and all(s.converged for s in self.steps)

    @property
    def residual_history(self) -> list:
        return [r for s in self.steps for r in s.residuals]


#: Halvings of a load step's increment allowed before the step is given up (1/1024 of it).
MAX_CUTS = 10


def solve_static(body: ElasticBody, dirichlet: Dirichlet | None = None, forces=None, *,
                 load_steps: int = 1, project: bool | str = True, rtol: float | None = None,
                 xtol: float = 1e-13, max_iterations: int = 50, armijo: float = 1e-4,
                 shrink: float = 0.5, max_backtracks: int = 40,
                 linear_solver: SolverSpec | str = "direct", x0=None,
                 on_step: Callable[[LoadStepRecord, np.ndarray], Any] | None = None,
                 stop: Callable[[], bool] | None = None, contact=None) -> StaticResult:
    """Static equilibrium of ``body`` under nodal ``forces`` ``(n, d)`` and ``dirichlet`` data.

    Parameters
    ----------
    body : ElasticBody
    dirichlet : Dirichlet, optional
        Prescribed displacements (rollers: some components only). Without any, the problem has
        rigid-body null modes: :class:`InputError`.
    forces : (n, d) array, optional
        External nodal forces (:func:`~femkit.solids.boundary.traction_forces`,
        :func:`~femkit.solids.boundary.body_forces`), dead loads.
    load_steps : int
        Number of equal load increments.
    project : bool or "auto"
        Element-wise PSD projection of the Hessian (default on: every direction is a descent
        direction, but Newton converges only linearly where the projection bites, e.g. the
        compressed side of a bent beam); ``"auto"``: the exact Hessian, and the projected one
        only for an iteration whose exact direction is not a descent direction (quadratic
        convergence near a stable equilibrium).
    rtol : float, optional
        Newton's relative residual tolerance (default
        :data:`~femkit.solvers.core.defaults.NEWTON_RTOL`, read at the call).
    linear_solver : SolverSpec or method name
        How each Newton system is solved (default a sparse direct solve).
    x0 : (n, d), optional
        Starting configuration (default the rest positions).
    on_step : callable, optional
        ``on_step(record, x)`` after each converged load step (``x`` ``(n, d)``, a copy).
    stop : callable, optional
        Checked before each Newton iteration; once it returns true the solve ends, returning
        the load steps completed so far (the one under way is dropped).
    contact : femkit.contact.barrier.BarrierModel, optional
        Barrier contact (IPC, Li et al. 2020) of the body's surface: its potential joins the
        total potential, every line search starts from the collision-free step size (CCD) of
        the Newton step, the stiffness is initialised by IPC's rule at the first iteration and
        updated after each; the start must be intersection-free. No friction in statics.

    Raises
    ------
    EquilibriumError
        Newton failed in a load step, or its increment, halved :data:`MAX_CUTS` times, still
        inverts elements (record and last equilibrium attached).
    """
    if project not in (True, False, "auto"):
        raise InputError(f"solve_static: project must be True, False or 'auto', got {project!r}")
    if load_steps < 1 or max_iterations < 1:
        raise InputError("solve_static: load_steps and max_iterations must be >= 1")
    if contact is not None and contact.moving:
        raise InputError("contact.obstacles: a moving obstacle (velocity, path, "
                         "angular_velocity) needs dynamics; the "
                         "static solver has no time to move it")
    if dirichlet is None or len(dirichlet.dofs) == 0:
        raise InputError("solve_static: prescribe some displacements (a free body has "
                         "rigid-body motions and no unique equilibrium)")
    if (dirichlet.n, dirichlet.dim) != (body.n, body.dim):
        raise InputError(f"Dirichlet data for {dirichlet.n} nodes in {dirichlet.dim}D, body has "
                         f"{body.n} in {body.dim}D")
    f_ext = np.zeros(body.ndof) if forces is None else np.asarray(forces, dtype=float).reshape(-1)
    if f_ext.shape != (body.ndof,) or not np.all(np.isfinite(f_ext)):
        raise InputError(f"forces must be finite with shape ({body.n}, {body.dim})")
    rtol = defaults.NEWTON_RTOL if rtol is None else rtol
    newton = _Newton(body, dirichlet, f_ext, project, rtol, xtol, max_iterations, armijo, shrink,
                     max_backtracks, SolverSpec(linear_solver) if isinstance(linear_solver, str)
                     else linear_solver, stop)
    newton.contact = contact
    x = body.rest_positions.reshape(-1).copy() if x0 is None else \
        np.array(x0, dtype=float).reshape(-1)
    records: list[LoadStepRecord] = []
    for k in range(1, load_steps + 1):
        rec = LoadStepRecord(k / load_steps)
        records.append(rec)
        try:
            x_new = newton.load_step(x, (k - 1) / load_steps, k / load_steps, rec)
        except _Stopped:
            records.pop()
            break
        except EquilibriumError as exc:
            exc.record, exc.load_step = _result(body, x, records), k
            exc.x = x.reshape(body.n, body.dim).copy()
            raise
        x = x_new
        if on_step is not None:
            on_step(rec, x.reshape(body.n, body.dim).copy())
    return _result(body, x, records)


class _Stopped(Exception):
    """A stop request seen between Newton iterations."""


class _Newton:
    """Newton's method with a line search on ``E(x) - f . x`` for one load step at a time, the
    step's increment spread into the body first and cut when it still inverts elements."""

    def __init__(self, body, dirichlet, f_ext, project, rtol, xtol, max_iterations, armijo,
                 shrink, max_backtracks, spec, stop):
        self.body, self.f_ext, self.project, self.spec, self.stop = body, f_ext, project, spec, stop
        self.rtol, self.xtol, self.max_iterations = rtol, xtol, max_iterations
        self.armijo, self.shrink, self.max_backtracks = armijo, shrink, max_backtracks
        self.X = body.rest_positions.reshape(-1)
        self.fixed, self.u_fixed, self.free = dirichlet.dofs, dirichlet.values, dirichlet.free()
        self.contact = None
        self.length = float(np.linalg.norm(np.ptp(body.rest_positions, axis=0)))
        # the size of the terms an energy density sums before they cancel near rest: (mu + lam) vol
        self.stored = float(sum((m.mu + abs(m.lam)) * body.rest.volumes[e].sum()
                                for e, m in body.groups))

    def potential(self, xf, f) -> tuple[float, float]:
        """Total potential and its round-off level (energies near equilibrium stop changing
        above it: Armijo's test gets that much slack, else Newton stalls at ~1e-8 residuals);
        ``inf`` where an element's energy is not finite (an inverted element of a ``log J``
        energy)."""
        try:
            e = float(self.body.evaluate(xf, 0)[0].sum())
        except SolverError:
            return np.inf, 0.0
        if self.contact is not None:
            e += self.contact.energy(xf)
        work = float(f @ xf)
        return e - work, 64 * np.finfo(float).eps * (abs(e) + abs(work) + self.stored)

    def spread(self, x: np.ndarray, lf: float) -> np.ndarray:
        """``x`` with the prescribed dofs moved to ``lf`` of their values and the free dofs
        moved with them: the linear elastic response ``H_ff dx_f = -H_fc dx_c`` of the projected
        tangent ``H`` at ``x`` (the previous equilibrium) to that increment ``dx_c``, so the
        layer of elements next to the held nodes is not crushed by their jump alone. Loads are
        left to Newton's line search. Without a prescribed increment: ``x`` unchanged."""
        fixed, free = self.fixed, self.free
        out = x.copy()
        dc = self.X[fixed] + lf * self.u_fixed - x[fixed]
        out[fixed] += dc
        if not np.any(dc) or not len(free):
            return out
        if self.contact is not None:   # a linear spread could pass through a contact
            if self.contact.max_step(x, out) < 1.0:
                raise EquilibriumError("static Newton: the prescribed increment of this load "
                                       "step would bring surfaces into contact; use more load "
                                       "steps")
            return out
        try:
            H = self.body.evaluate(x, 2, project=True)[2].tocsr()
            sol = self.spec.solve(H[free][:, free].tocsr(), -(H[free][:, fixed] @ dc))
        except SolverError:   # the jump of the held nodes alone, cut below if it inverts
            return out
        if np.all(np.isfinite(sol.x)):
            out[free] += sol.x
        return out

    def load_step(self, x: np.ndarray, lf0: float, lf1: float, rec: LoadStepRecord) -> np.ndarray:
        """The equilibrium at load factor ``lf1`` from the one at ``lf0``: sub-steps, the first
        the whole increment, each halved (``rec.substeps`` counts them) while its spread start
        has an element of non-finite energy."""
        a, h, cuts = lf0, lf1 - lf0, 0
        rec.substeps = 0
        while a < lf1:
            b = lf1 if a + h >= lf1 * (1 - 1e-12) else a + h
            start = self.spread(x, b)
            if not np.isfinite(self.potential(start, b * self.f_ext)[0]):
                if cuts == MAX_CUTS:
                    raise EquilibriumError(
                        f"static Newton: the increment of the load step to load factor {lf1:g} "
                        f"inverts elements even cut {2 ** MAX_CUTS} times (energy not finite "
                        f"from load factor {a:g} to {b:g})")
                h, cuts = h / 2, cuts + 1
                continue
            x = self.newton(start, b * self.f_ext, rec)
            rec.substeps += 1
            a = b
        rec.converged = True
        return x

    def newton(self, x: np.ndarray, f: np.ndarray, rec: LoadStepRecord) -> np.ndarray:
        """Newton iterations on the free dofs from the admissible ``x`` (prescribed dofs in
        place) to the equilibrium under ``f``; raises :class:`EquilibriumError`."""
        body, free, spec = self.body, self.free, self.spec
        pot, noise = self.potential(x, f)
        r_ref, step = None, np.inf
        for it in range(self.max_iterations + 1):
            if self.stop is not None and self.stop():
                raise _Stopped
            _, g, H, _ = body.evaluate(x, 2, project=self.project is True)
            if self.contact is not None:
                g, H = self._with_contact(x, g, H, f)
            r = g.reshape(-1) - f
            res = float(np.linalg.norm(r[free]))
            rec.residuals.append(res)
            if r_ref is None:
                r_ref = max(float(np.linalg.norm(f[free])), res, 1e-300)
            if res <= self.rtol * r_ref or step <= self.xtol * self.length:
                return x
            if it == self.max_iterations:
                break
            rec.iterations += 1
            sol = spec.solve(H[free][:, free].tocsr(), -r[free])
            slope = float(r[free] @ sol.x)
            if self.project == "auto" and not (slope < 0.0 and np.all(np.isfinite(sol.x))):
                H = body.evaluate(x, 2, project=True)[2]
                if self.contact is not None:
                    H = H + self.contact.hessian(x, project=True)
                sol = spec.solve(H[free][:, free].tocsr(), -r[free])
                slope = float(r[free] @ sol.x)
                rec.projected += 1
            dx = np.zeros_like(x)
            dx[free] = sol.x
            t0 = 1.0 if self.contact is None else self.contact.max_step(x, x + dx)
            t, p_try, noise_try = self.line_search(x, dx, f, pot, noise, slope, res, rec, t0)
            rec.step_lengths.append(t)
            x = x + t * dx
            pot, noise = p_try, noise_try
            if self.contact is not None and self.contact.update_stiffness(x):
                pot, noise = self.potential(x, f)
            step = float(np.abs(dx).max(initial=0.0))      # the Newton step, not t * dx
        raise EquilibriumError(
            f"static Newton: no convergence in {self.max_iterations} iterations in the load step "
            f"to load factor {rec.load_factor:g} (residual {rec.residuals[-1]:.3e}, start "
            f"{rec.residuals[0]:.3e})")

    def _with_contact(self, x, g, H, f):
        """The body's gradient and Hessian plus the barrier's (its stiffness set by IPC's rule
        at the first call); the Hessian's contact blocks PSD-projected as the body's are."""
        c = self.contact
        if c.kappa is None:
            mass = float(np.mean(self.body.lumped_masses()))
            c.init_stiffness(g.reshape(-1) - f, mass, 1.0, x)
        g = g + c.gradient(x).reshape(g.shape)
        return g, H + c.hessian(x, project=self.project is not False)

    def line_search(self, x, dx, f, pot, noise, slope, res, rec,
                    t_max: float = 1.0) -> tuple[float, float, float]:
        """Armijo backtracking (Nocedal & Wright, section 3.1) from ``t_max`` (with contact the
        collision-free step size) with the round-off slack; when it finds no decrease, the
        largest step if it lowers the residual norm; ``(t, potential, noise)`` of the accepted
        step; :class:`EquilibriumError` when there is none."""
        t = t_max
        if slope < 0.0:
            for _ in range(self.max_backtracks):
                p_try, noise_try = self.potential(x + t * dx, f)
                if p_try <= pot + self.armijo * t * slope + max(noise, noise_try):
                    return t, p_try, noise_try
                t *= self.shrink
            # energy differences below rounding: accept a full step that lowers |r|
            p_try, noise_try = self.potential(x + t_max * dx, f)
            lowers = False
            if np.isfinite(p_try):
                g_try = self.body.evaluate(x + t_max * dx, 1)[1].reshape(-1) - f
                if self.contact is not None:
                    g_try = g_try + self.contact.gradient(x + t_max * dx).reshape(-1)
                lowers = bool(np.linalg.norm(g_try[self.free]) < (1.0 - self.armijo) * res)
            if not lowers:
                raise EquilibriumError(
                    f"static Newton: line search found no decrease in the load step to load "
                    f"factor {rec.load_factor:g} (iteration {rec.iterations}, residual {res:.3e}; "
                    f"residuals {', '.join(f'{v:.2e}' for v in rec.residuals[-6:])})")
            return t_max, p_try, noise_try
        # not a descent direction (projection off): the full Newton step
        p_try, noise_try = self.potential(x + t_max * dx, f)
        if not np.isfinite(p_try):
            raise EquilibriumError(f"static Newton: energy not finite in the load step to load "
                                   f"factor {rec.load_factor:g}")
        return t_max, p_try, noise_try


def _result(body: ElasticBody, x: np.ndarray, records) -> StaticResult:
    xs = x.reshape(body.n, body.dim).copy()
    return StaticResult(xs, xs - body.rest_positions, records, float(body.energy(xs)))
