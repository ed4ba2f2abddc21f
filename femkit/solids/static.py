"""Quasi-static equilibrium: ``min_x E(x) - f . x`` with prescribed displacements, by Newton's
method with a backtracking line search and load stepping.

Load step ``k = 1..K`` applies ``k/K`` of the external forces and of the prescribed
displacements; each is solved from the previous equilibrium (prescribed dofs moved to their new
values) by Newton iterations on the free dofs: ``H_ff dx = -r_f`` with the element-wise
PSD-projected Hessian (Teran et al. 2005; ``project=True`` by default, so ``dx`` is a descent
direction), then Armijo backtracking on the total potential (Nocedal & Wright, Numerical
Optimization, section 3.1), as :mod:`femkit.dynamics.integrators.newton` does for implicit
Euler; the Armijo test allows the round-off level of the potential
(``64 eps (|E| + |f.x| + sum (mu + |lam|) vol)``, the last term the size of the terms an energy
density sums before they cancel near rest), and when even that finds no decrease, a full step
that lowers the residual norm is taken: without these Newton stalls where energy differences
drown in rounding while the residual is still ~1e-8 relative. Converged when ``|r_f| <= rtol max(|f_k|, |r_0|)`` (``r_0``: residual at the start of
the load step) or the step ``|dx|_inf <= xtol L`` (``L`` the bounding-box diagonal).

Failure -- a line search that finds no decrease, the iteration limit, an energy that is not
finite -- raises :class:`~femkit.errors.EquilibriumError` carrying the record so far (load steps
done, iterations, residual histories) and the last equilibrium.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import EquilibriumError, InputError, SolverError
from ..solvers.spec import SolverSpec
from .body import ElasticBody
from .boundary import Dirichlet

__all__ = ["StaticResult", "LoadStepRecord", "solve_static"]


@dataclass
class LoadStepRecord:
    """One load step: its factor, Newton iterations, residual norms (one per iterate, the first
    before any step), accepted step lengths ``t`` of the line search, whether it converged and
    (``project="auto"``) how many iterations fell back to the projected Hessian."""

    load_factor: float
    iterations: int = 0
    residuals: list = field(default_factory=list)
    step_lengths: list = field(default_factory=list)
    converged: bool = False
    projected: int = 0


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


def solve_static(body: ElasticBody, dirichlet: Dirichlet | None = None, forces=None, *,
                 load_steps: int = 1, project: bool | str = True, rtol: float = 1e-12,
                 xtol: float = 1e-13, max_iterations: int = 50, armijo: float = 1e-4,
                 shrink: float = 0.5, max_backtracks: int = 40,
                 linear_solver: SolverSpec | str = "direct", x0=None) -> StaticResult:
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
    linear_solver : SolverSpec or method name
        How each Newton system is solved (default a sparse direct solve).
    x0 : (n, d), optional
        Starting configuration (default the rest positions).

    Raises
    ------
    EquilibriumError
        Newton failed in a load step (record and last equilibrium attached).
    """
    if project not in (True, False, "auto"):
        raise InputError(f"solve_static: project must be True, False or 'auto', got {project!r}")
    if load_steps < 1 or max_iterations < 1:
        raise InputError("solve_static: load_steps and max_iterations must be >= 1")
    if dirichlet is None or len(dirichlet.dofs) == 0:
        raise InputError("solve_static: prescribe some displacements (a free body has "
                         "rigid-body motions and no unique equilibrium)")
    if (dirichlet.n, dirichlet.dim) != (body.n, body.dim):
        raise InputError(f"Dirichlet data for {dirichlet.n} nodes in {dirichlet.dim}D, body has "
                         f"{body.n} in {body.dim}D")
    spec = SolverSpec(linear_solver) if isinstance(linear_solver, str) else linear_solver
    X = body.rest_positions.reshape(-1)
    f_ext = np.zeros(body.ndof) if forces is None else np.asarray(forces, dtype=float).reshape(-1)
    if f_ext.shape != (body.ndof,) or not np.all(np.isfinite(f_ext)):
        raise InputError(f"forces must be finite with shape ({body.n}, {body.dim})")
    fixed, u_fixed = dirichlet.dofs, dirichlet.values
    free = dirichlet.free()
    length = float(np.linalg.norm(np.ptp(body.rest_positions, axis=0)))
    x = X.copy() if x0 is None else np.array(x0, dtype=float).reshape(-1)
    records: list[LoadStepRecord] = []
    # the size of the terms an energy density sums before they cancel near rest: (mu + lam) vol
    stored = float(sum((m.mu + abs(m.lam)) * body.rest.volumes[e].sum() for e, m in body.groups))

    def potential(xf, f):
        """Total potential and its round-off level (energies near equilibrium stop changing
        above it: Armijo's test gets that much slack, else Newton stalls at ~1e-8 residuals)."""
        try:
            e = float(body.evaluate(xf, 0)[0].sum())
        except SolverError:
            return np.inf, 0.0
        work = float(f @ xf)
        return e - work, 64 * np.finfo(float).eps * (abs(e) + abs(work) + stored)

    for k in range(1, load_steps + 1):
        lf = k / load_steps
        f = lf * f_ext
        rec = LoadStepRecord(lf)
        records.append(rec)
        x_start = x.copy()
        x[fixed] = X[fixed] + lf * u_fixed
        pot, noise = potential(x, f)
        r_ref = None
        for it in range(max_iterations + 1):
            _, g, H, _ = body.evaluate(x, 2, project=project is True)
            r = g.reshape(-1) - f
            res = float(np.linalg.norm(r[free]))
            rec.residuals.append(res)
            if r_ref is None:
                r_ref = max(float(np.linalg.norm(f[free])), res, 1e-300)
            if res <= rtol * r_ref or (it and step <= xtol * length):
                rec.converged = True
                break
            if it == max_iterations:
                break
            rec.iterations += 1
            sol = spec.solve(H[free][:, free].tocsr(), -r[free])
            slope = float(r[free] @ sol.x)
            if project == "auto" and not (slope < 0.0 and np.all(np.isfinite(sol.x))):
                H = body.evaluate(x, 2, project=True)[2]
                sol = spec.solve(H[free][:, free].tocsr(), -r[free])
                slope = float(r[free] @ sol.x)
                rec.projected += 1
            dx = np.zeros_like(x)
            dx[free] = sol.x
            t = 1.0
            if slope < 0.0:
                for _ in range(max_backtracks):
                    p_try, noise_try = potential(x + t * dx, f)
                    if p_try <= pot + armijo * t * slope + max(noise, noise_try):
                        break
                    t *= shrink
                else:
                    # energy differences below rounding: accept a full step that lowers |r|
                    g_try = body.evaluate(x + dx, 1)[1].reshape(-1) - f
                    t = 1.0
                    p_try, noise_try = potential(x + dx, f)
                    if not np.linalg.norm(g_try[free]) < (1.0 - armijo) * res:
                        raise EquilibriumError(
                            f"static Newton: line search found no decrease in load step "
                            f"{k}/{load_steps} (iteration {it + 1}, residual {res:.3e}; residuals "
                            f"{', '.join(f'{v:.2e}' for v in rec.residuals[-6:])})",
                            _result(body, x_start, records), k, x_start.reshape(body.n, body.dim))
            else:  # not a descent direction (projection off): the full Newton step
                p_try, noise_try = potential(x + dx, f)
            if not np.isfinite(p_try):
                raise EquilibriumError(f"static Newton: energy not finite in load step {k}",
                                       _result(body, x_start, records), k,
                                       x_start.reshape(body.n, body.dim))
            rec.step_lengths.append(t)
            x = x + t * dx
            pot, noise = p_try, noise_try
            step = float(np.abs(dx).max(initial=0.0))      # the Newton step, not t * dx
        if not rec.converged:
            raise EquilibriumError(
                f"static Newton: no convergence in {max_iterations} iterations in load step "
                f"{k}/{load_steps} (residual {rec.residuals[-1]:.3e}, start {rec.residuals[0]:.3e})",
                _result(body, x_start, records), k, x_start.reshape(body.n, body.dim))
    return _result(body, x, records)


def _result(body: ElasticBody, x: np.ndarray, records) -> StaticResult:
    xs = x.reshape(body.n, body.dim).copy()
    return StaticResult(xs, xs - body.rest_positions, records, float(body.energy(xs)))
