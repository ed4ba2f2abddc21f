"""Full multigrid (FMG, nested iteration with V-cycles) stopped at the discretisation error.

Brandt's full multigrid (Brandt, "Multi-level adaptive solutions to boundary-value problems",
Math. Comp. 31, 1977; Briggs, Henson and McCormick, *A Multigrid Tutorial*, 2000, ch. 3;
Trottenberg, Oosterlee and Schüller, *Multigrid*, 2001, sec. 2.6): solve on the coarsest mesh,
interpolate to the next (exact P1 prolongation), improve with V-cycles there, and so on up to the
finest mesh. Each level stops as soon as its algebraic error is a fraction of its discretisation
error, so the whole solve costs a few V-cycles on the finest mesh (O(n)).

Stopping test on level ``l`` (energy norm ``||v||_A = sqrt(v^T A v)``, computed with explicit
products, no extra sweep):

* discretisation-error estimate ``eta_l = ||x_l - x_l^0||_A / sqrt(3)``, ``x_l^0`` the start
  interpolated from level ``l - 1``: Galerkin orthogonality of nested spaces with an H1 error
  halving with ``h`` gives ``||u_l - u_{l-1}||_A^2 = 3 ||u - u_l||_A^2``; a solution with a corner
  singularity converges more slowly, which makes ``eta`` smaller, the test stricter;
* algebraic-error bound ``||x - A^-1 b||_A <= rho / (1 - rho) ||d||_A`` with ``d`` the last
  V-cycle's increment and ``rho`` the cycle's contraction: measured once at setup by a few power
  steps of the error propagator on a small level (at least :data:`RHO_FLOOR`), raised by the
  ratio of successive increments observed on every level;
* stop when the bound is at most ``fraction * eta_l`` (default :data:`DEFAULT_FRACTION` = 0.1: in
  practice two V(2,2)-cycles per level, L2 and max-nodal errors within 2% of the exact discrete
  solution's).

The coarse-level right-hand sides: by default ``b_l = P_l^T b_{l+1}`` on the free nodes (with
Galerkin operators this is the fine problem projected onto the coarse space, exact full multigrid
for homogeneous Dirichlet data). A caller with the per-level systems (the case pipeline assembles
every level: a third of the fine assembly) passes ``levels=[sys_0, ..., sys_{L-1}]``
(:class:`~femkit.fem.DirichletSystem`), whose ``b`` and Dirichlet values (``expand``) are then
used: right for inhomogeneous Dirichlet data too. Without them, the Dirichlet data alone
(``dirichlet=``: the finest level's nodal values, read at its fixed nodes) gives the same coarse
problems algebraically: level ``l`` takes its Dirichlet values by injection, ``g_l``, and its
right-hand side is the restricted residual of their interpolant,
``b_l = P_l^T (b_{l+1} - A_{l+1} w)`` with ``w = (P_l g_l)`` on the free nodes of level ``l + 1``:
the Galerkin projection of the finer problem with the boundary values of ``g_l`` (they differ from
the finer level's by the interpolation error of ``g`` along the boundary, O(h^2), as the level
systems' own quadrature does). One product with every level's operator, no assembly.
Restricted right-hand sides of a system with inhomogeneous Dirichlet data and neither argument
carry the lifting's boundary layer to the coarse levels: the estimate then grows under refinement
instead of falling, FMG notices (:data:`ESTIMATE_DECAY`) and stops by the residual rule only
(``info["estimate_credible"] = False``).

Certification: ``converged`` is true when the true residual ``||b - A x||``, recomputed at exit,
meets the usual rule ``max(rtol ||b||, atol)``, or (``target="discretisation"``, the default)
when the estimate test above passed on the finest level and the recomputed true residual agrees
with the tracked one (no round-off drift, within a factor 2). ``target="residual"`` keeps cycling
on the finest level until the residual rule alone holds.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import InputError
from .core.checks import dependency_boundary, finish, prepare, zero_rhs_result
from .core.norms import ldexp_saturating, norm2, scaled, unscale, unscale_all
from .core.result import SolveResult

#: Default ratio of algebraic to estimated discretisation error (energy norm) at which FMG stops.
#: The energy norm is dominated by the high frequencies of the discretisation error, while the
#: algebraic error left by a V-cycle is smooth (large in L2 for its energy): 0.5 stopped after one
#: V-cycle per level with an L2 error 1.27x the exact discrete solution's (unit square, 5 levels);
#: 0.1 takes two and reaches 1.01x.
DEFAULT_FRACTION = 0.1
#: Smallest contraction the algebraic-error bound assumes: the V(2,2)-cycle's measured asymptotic
#: energy-norm factor on fine levels is 0.10-0.14 (unit square, L-shape, annulus), while the power
#: steps at setup run on a small level, where it is lower.
RHO_FLOOR = 0.1
#: The discretisation-error estimate must fall by at least this factor per refinement to be
#: trusted (an H1 error ~ h^s falls by 2^-s; s >= 1/2 for the singularities of polygonal domains
#: gives <= 0.71). It grows instead when the coarse right-hand sides were restricted from a system
#: with inhomogeneous Dirichlet data (the boundary layer of the lifting); FMG then stops by the
#: residual rule only.
ESTIMATE_DECAY = 0.9
#: Largest number of V-cycles on a level below the finest.
MAX_LEVEL_CYCLES = 20


def _contraction(mg, *, max_size: int = 20000, steps: int = 6, draw: int = 0) -> float:
    """Energy-norm contraction of the V-cycle error propagator ``I - M A`` on the finest level
    with at most ``max_size`` unknowns (level >= 1), by ``steps`` power steps from a random start."""
    lvl = 0
    for k in range(1, mg.n_levels):
        if mg.levels[k].A.shape[0] <= max_size or k == 1:
            lvl = k
    if lvl == 0:
        return 0.0
    A = mg.levels[lvl].A
    e = np.random.default_rng(draw).standard_normal(A.shape[0])
    rho = 0.0
    for _ in range(steps):
        Ae = A @ e
        nrm = math.sqrt(max(float(e @ Ae), 0.0))
        if nrm == 0.0:
            return 0.0
        e /= nrm
        Ae /= nrm
        e = e - mg.vcycle(Ae, lvl)
        rho = math.sqrt(max(float(e @ (A @ e)), 0.0))
    return rho


def default_sweeps(hierarchy, consistent: bool = True) -> int:
    """Smoothing sweeps of fmg's V-cycles: 2 (V(2,2)) on triangles, 1 (V(1,1)) on tetrahedra
    when the coarse problems are consistent (``consistent``: level systems or Dirichlet data
    given; plain restriction of a right-hand side with inhomogeneous Dirichlet data can pass the
    estimate test with a wrong coarse solution, 2.2x the discrete error at 4 levels under
    V(1,1), and keeps V(2,2)).

    On nested Kuhn cubes (u = exp(x + y/2 - 3z/10), 2 to 6 levels, fraction 0.1) V(1,1) stops
    after two cycles per level with the L2 error within 1.01x of the discrete solution's on every
    level, for 9 matrix passes per level; V(2,2) takes two cycles too (13 passes; 1.006x), and one
    V(2,2) per level (7 passes) drifts from 1.00x to 1.09x as levels are added. A tetrahedral row
    has ~15 entries against ~7 on triangles, so every sweep costs twice as much in 3D."""
    finest = getattr(hierarchy, "finest", None)
    return 1 if consistent and getattr(finest, "dim", 2) == 3 else 2


def _coarse_dirichlet(mg, values) -> list[np.ndarray]:
    """The Dirichlet values of every level below the finest, coarsest first, each a full nodal
    vector that is zero on the level's free nodes (the finest level's fixed values, injected)."""
    H = mg.hierarchy
    n = H.finest.n_points
    g = np.asarray(values, dtype=np.float64)
    if g.shape != (n,):
        raise InputError(f"fmg: dirichlet must hold one value per node of the finest mesh "
                         f"({n}), got shape {g.shape}")
    g = g.copy()
    g[mg.frees[-1]] = 0.0
    if not np.isfinite(g).all():
        raise InputError(f"fmg: dirichlet is not finite at {int((~np.isfinite(g)).sum())} "
                         f"fixed node(s)")
    out = []
    for lvl in range(mg.n_levels - 2, -1, -1):
        g = g[H.injections[lvl]]      # a coarse node is fixed when the node it becomes is
        out.append(g)
    return out[::-1]


def fmg(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None,
        maxiter: int | None = None, M=None, callback=None, hierarchy=None, free=None,
        levels=None, dirichlet=None, sweeps: int | None = None,
        omega: float | None = None, fraction: float = DEFAULT_FRACTION,
        target: str = "discretisation", check_symmetry: bool = True) -> SolveResult:
    """Full multigrid on a nested mesh hierarchy, stopped at the discretisation error.

    Parameters
    ----------
    A : sparse matrix
        The system on the free nodes of ``hierarchy.finest`` (symmetric positive definite).
    b : ndarray
    x0 : ignored
        Accepted for signature uniformity: FMG starts from the coarsest level.
    rtol, atol : float
        The residual rule ``||b - A x|| <= max(rtol ||b||, atol)``: meeting it also stops and
        certifies; with ``target="residual"`` it is the only stopping test.
    maxiter : int, optional
        V-cycles on the finest level at most (default 50).
    M : Preconditioner, optional
        A ``gmg`` preconditioner built for this ``A`` (reuses its multigrid setup); default: built here.
    callback : callable, optional
        ``callback(x)`` after every V-cycle on the finest level.
    hierarchy : MeshHierarchy
        Required (without it :class:`~femkit.errors.HierarchyError` names ``amg_rs``).
    free : array of int or bool mask, optional
        Free nodes of the finest mesh (``DirichletSystem.free``); default all.
    levels : list of DirichletSystem, optional
        The systems of levels ``0 .. L-1`` (coarsest first) on the hierarchy's meshes: their
        ``b`` and Dirichlet values replace ``P^T b`` restriction (see the module docstring).
    dirichlet : ndarray, optional
        Nodal values on ``hierarchy.finest`` (one per node), read at the fixed (non-free) nodes
        only: the Dirichlet data, e.g. ``sys.expand(np.zeros(len(sys.free)))``. The coarse
        problems then get these boundary values and consistent right-hand sides without level
        systems (module docstring); not together with ``levels``.
    sweeps, omega : int, float
        Smoothing of the V(sweeps, sweeps)-cycle (:func:`femkit.solvers.gmg.build`);
        default :func:`default_sweeps` (2 on triangles, 1 on tetrahedra given ``levels`` or
        ``dirichlet``).
    fraction : float
        Stop a level when the algebraic-error bound is at most ``fraction`` x the estimated
        discretisation error (energy norm), in (0, 1].
    target : {"discretisation", "residual"}
    check_symmetry : bool
        Check ``A`` for symmetry once.

    Returns
    -------
    SolveResult
        ``iterations``: V-cycles on the finest level; ``residuals``: the finest level's residual
        norms from the interpolated start; ``info``: ``cycles_per_level``, ``sizes``,
        ``algebraic_error_estimate`` and ``discretisation_error_estimate`` (energy norm, finest
        level), ``rho`` (contraction used), ``target``, ``fraction``, ``stopped_by`` and the
        multigrid facts (levels, operator complexity ...).

    Examples
    --------
    >>> import numpy as np
    >>> from femkit.mesh import Mesh, MeshHierarchy, boundary_nodes
    >>> from femkit.fem import assemble_stiffness, assemble_load, apply_dirichlet
    >>> sq = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])
    >>> H = MeshHierarchy.from_refinement(sq, 6)
    >>> m = H.finest
    >>> sys = apply_dirichlet(assemble_stiffness(m), assemble_load(m, 1.0), boundary_nodes(m), 0.0)
    >>> res = fmg(sys.A, sys.b, hierarchy=H, free=sys.free)
    >>> res.converged, res.iterations <= 2, res.info["stopped_by"]
    (True, True, 'discretisation-error estimate')
    """
    t_setup = time.perf_counter()
    _check_options(target, fraction)
    prob = prepare(A, b, None, rtol=rtol, atol=atol, maxiter=50 if maxiter is None else maxiter,
                   method="fmg", symmetric=True, check_symmetry=check_symmetry)
    prob.x = None  # FMG starts from the coarsest level: no zero start vector of n floats
    mg = _multigrid(prob, M, hierarchy, free, sweeps, omega,
                    consistent=levels is not None or dirichlet is not None)
    coarse = _CoarseData(mg, levels, dirichlet)
    rho0 = max(_contraction(mg), RHO_FLOOR)
    setup_time = time.perf_counter() - t_setup
    if prob.b_is_zero:
        res = zero_rhs_result(prob, method="fmg")
        res.setup_time = setup_time
        return res
    run = _Run(prob, mg, rho0, target=target, fraction=fraction, callback=callback)
    _cycle_levels(run, _LevelProblems(run, coarse))  # its right-hand sides go on return
    res = _certify(run, fraction)
    res.info.update(mg.info)
    res.info.update(_run_info(run, rho0, fraction, coarse))
    res.setup_time = setup_time
    res.solve_time = time.perf_counter() - prob.t_start - setup_time
    return res


def _check_options(target: str, fraction) -> None:
    """Reject a ``target`` other than the two stopping rules and a ``fraction`` outside (0, 1]."""
    if target not in ("discretisation", "residual"):
        raise InputError(f"fmg: target must be 'discretisation' or 'residual', got {target!r}")
    try:
        frac_ok = 0.0 < float(fraction) <= 1.0
    except (TypeError, ValueError):
        frac_ok = False
    if not frac_ok:
        raise InputError(f"fmg: fraction must be a number in (0, 1], got {fraction!r}")


def _multigrid(prob, M, hierarchy, free, sweeps, omega, *, consistent: bool):
    """The multigrid set-up: the one a ``gmg`` preconditioner ``M`` holds (checked against the
    system), else built here on ``hierarchy`` (:func:`default_sweeps` unless ``sweeps``)."""
    from .gmg import DEFAULT_OMEGA, Multigrid, _hierarchy_error

    mg = getattr(M, "info", {}).get("hierarchy") if M is not None else None
    if M is not None and not isinstance(mg, Multigrid):
        raise InputError("fmg: M must be a 'gmg' preconditioner of this system (or None)")
    if mg is None:
        if hierarchy is None:
            raise _hierarchy_error("method 'fmg'")
        with dependency_boundary("fmg (multigrid set-up)", prob.A):
            if sweeps is None:
                sweeps = default_sweeps(hierarchy, consistent)
            mg = Multigrid(prob.A, hierarchy, free=free, sweeps=sweeps,  # symmetry checked above
                           omega=DEFAULT_OMEGA if omega is None else omega, check_symmetry=False)
    elif mg.levels[-1].A.shape != prob.A.shape:
        raise InputError(f"fmg: M was built for {mg.levels[-1].A.shape}, A is {prob.A.shape}")
    return mg


class _CoarseData:
    """What the coarse problems are made of besides ``P^T``: the caller's level systems
    (``levels``) or the finest level's Dirichlet data injected to every level (``dirichlet``),
    checked against the hierarchy, with the prolongations' fixed columns that carry either."""

    def __init__(self, mg, levels, dirichlet) -> None:
        top = mg.n_levels - 1
        if levels is not None:
            levels = list(levels)
            if len(levels) != top:
                raise InputError(f"fmg: levels must hold the {top} systems below the finest "
                                 f"(coarsest first), got {len(levels)}")
            for lvl, s in enumerate(levels):
                if len(s.b) != len(mg.frees[lvl]):
                    raise InputError(f"fmg: level {lvl} system has {len(s.b)} unknowns, the "
                                     f"hierarchy's level {lvl} has {len(mg.frees[lvl])} free "
                                     f"nodes")
        if dirichlet is not None:
            if levels is not None:
                raise InputError("fmg: give either levels (the coarse systems) or dirichlet (the "
                                 "finest level's Dirichlet values), not both")
            dirichlet = _coarse_dirichlet(mg, dirichlet)
        self.levels, self.dirichlet = levels, dirichlet
        # the coarse Dirichlet values reach the finer free nodes through the few entries of the
        # prolongations with a fixed column (not the full matrices and nodal vectors)
        self.fixed_parts = (mg.hierarchy.fixed_prolongations(frees=mg.frees)
                            if levels is not None or dirichlet is not None else None)
        self.lifted = None
        if levels is not None:
            # each level's Dirichlet values at its fixed nodes (None where all are zero)
            lifted = [sy.expand(np.zeros(len(sy.free)))[fx]
                      for sy, (_, fx) in zip(levels, self.fixed_parts)]
            self.lifted = [g if np.any(g) else None for g in lifted]

    def describe(self) -> str:
        """How the coarse right-hand sides were made (``info["coarse_rhs"]``)."""
        return ("level systems" if self.levels is not None else
                "restricted, Dirichlet data injected" if self.dirichlet is not None
                else "restricted (P^T b)")


class _Run:
    """The state of one FMG solve across its levels: cycles, contraction, estimates, the finest
    level's residual history and the verdict so far (all norms in the normalised units)."""

    def __init__(self, prob, mg, rho0: float, *, target: str, fraction,
                 callback) -> None:
        self.prob, self.mg, self.top = prob, mg, mg.n_levels - 1
        self.target, self.fraction, self.callback = target, fraction, callback
        # right-hand sides normalised by 2^-e (norms.binary_exponent: exact, so the cycles are
        # those on b and the energy norms stay far from under/overflow)
        self.e = prob.exponent
        self.tol = ldexp_saturating(prob.tolerance, -self.e)
        self.cycles, self.rho = [0] * (self.top + 1), rho0
        self.etas = [float("nan")] * (self.top + 1)
        self.credible = True
        self.alg = self.eta = float("nan")
        self.residuals: list[float] = []
        self.stopped_by, self.reason, self.message = "maxiter", "maxiter", ""
        self.met = False


class _LevelProblems:
    """The right-hand side and the interpolated start of every level, coarsest first."""

    def __init__(self, run: _Run, coarse: _CoarseData) -> None:
        mg, e, top = run.mg, run.e, run.top
        self.mg, self.b, self.e, self.top, self.coarse = mg, run.prob.b, e, top, coarse
        rhs = [None] * (top + 1)
        rhs[top] = scaled(self.b, -e)
        for lvl in range(top - 1, -1, -1):
            if coarse.levels is not None:
                rhs[lvl] = scaled(coarse.levels[lvl].b, -e)
            elif coarse.dirichlet is not None:
                Pd, fixed = coarse.fixed_parts[lvl]
                w = Pd @ scaled(coarse.dirichlet[lvl][fixed], -e)
                rhs[lvl] = mg.restrictions[lvl] @ (rhs[lvl + 1] - mg.levels[lvl + 1].A @ w)
            else:
                rhs[lvl] = mg.restrictions[lvl] @ rhs[lvl + 1]
        # the finest right-hand side is b times 2^-e (exact): formed when needed, not kept beside b
        rhs[top] = None
        self.rhs = rhs

    def start(self, lvl: int, xc: np.ndarray) -> np.ndarray:
        """Level ``lvl``'s start interpolated from the coarser level's ``xc``: ``(P u)[free] =
        P xc + Pd g`` for ``u = (xc on the free nodes, g on the fixed ones)``, the same sums as
        the full product (a row has at most two entries), ``g`` in b's units times 2^-e. Formed
        again where it is needed (the same numbers), not kept."""
        c, e = self.coarse, self.e
        x0 = self.mg.prolongations[lvl - 1] @ xc
        if c.levels is not None and c.lifted[lvl - 1] is not None:
            x0 += c.fixed_parts[lvl - 1][0] @ scaled(c.lifted[lvl - 1], -e)
        elif c.dirichlet is not None:
            Pd, fixed = c.fixed_parts[lvl - 1]
            x0 += Pd @ scaled(c.dirichlet[lvl - 1][fixed], -e)
        return x0

    def level_rhs(self, lvl: int) -> np.ndarray:
        """A new array holding level ``lvl``'s right-hand side (the caller may overwrite it)."""
        return np.ldexp(self.b, -self.e) if lvl == self.top else self.rhs[lvl].copy()


def _cycle_levels(run: _Run, problems: _LevelProblems) -> None:
    """Nested iteration: the coarsest level solved, every finer level started from the coarser
    solution and cycled until its stopping test; the finest level's solution in ``prob.x``."""
    mg, prob, top = run.mg, run.prob, run.top
    x = mg.vcycle(problems.rhs[0], 0) if top > 0 else None
    if top == 0:  # one level: the coarse factorisation is a direct solve
        prob.x = mg.vcycle(prob.b, 0)
        run.residuals = [norm2(prob.b - prob.A @ prob.x)]
        run.stopped_by, run.reason = "direct coarse solve", "converged"
    for lvl in range(1, top + 1):
        x = _cycle_level(run, problems, lvl, x)


def _cycle_level(run: _Run, problems: _LevelProblems, lvl: int,
                 x_coarse: np.ndarray) -> np.ndarray:
    """V-cycles on level ``lvl`` from the start interpolated from ``x_coarse`` until the level's
    stopping test (the finest: the verdict tests of :func:`_finest_test`); returns its solution."""
    mg, e = run.mg, run.e
    x = problems.start(lvl, x_coarse)    # the start x0 of this level
    r = problems.level_rhs(lvl)
    r -= mg.matvec(x, lvl)
    # ||x - x0||_A^2 = (x - x0).(r0 - r) = x.r0 - x.r - x0.r0 + x0.r: dot products
    r0 = r.copy()
    s00 = float(x @ r0)
    started = bool(np.any(x))  # else eta measures the solution, not an error
    finest = lvl == run.top
    if finest:
        run.residuals.append(norm2(r))
    last_true = None    # true residual at the last residual replacement (finest level)
    limit = run.prob.maxiter if finest else MAX_LEVEL_CYCLES
    prev_d = None
    while run.cycles[lvl] < limit:
        d = mg.vcycle(r, lvl)
        Ad = mg.matvec(d, lvl)   # in the level's work vector: free until the next cycle
        x += d
        r -= Ad
        run.cycles[lvl] += 1
        dA = math.sqrt(max(float(d @ Ad), 0.0))
        d = Ad = None  # released before the next cycle, the start or the true residual
        if prev_d is not None and prev_d > 0:
            run.rho = max(run.rho, min(dA / prev_d, 0.99))
        prev_d = dA
        run.alg = run.rho / (1.0 - run.rho) * dA
        x0_r = float(problems.start(lvl, x_coarse) @ r)
        run.eta = math.sqrt(max(float(x @ r0) - float(x @ r) - s00 + x0_r, 0.0) / 3.0)
        if finest:
            stop, r, last_true = _finest_test(run, problems, x, r, last_true, started)
            if stop:
                break
        elif _lower_level_done(run, lvl, started):
            break
    # a start of zeros (the coarser level had no free node) estimates nothing
    run.etas[lvl] = run.eta if started else float("nan")
    if math.isfinite(run.etas[lvl - 1]) and not run.eta <= ESTIMATE_DECAY * run.etas[lvl - 1]:
        run.credible = False  # from now on only the residual rule stops
    if finest:
        run.prob.x = scaled(x, e)
        if not run.met and run.reason == "maxiter":
            run.message = (f"maxiter = {run.prob.maxiter} V-cycles on the finest level reached; "
                           f"algebraic error bound {unscale(run.alg, e):.3e}, estimated "
                           f"discretisation error {unscale(run.eta, e):.3e}")
    return x


def _lower_level_done(run: _Run, lvl: int, started: bool) -> bool:
    """Whether level ``lvl`` below the finest has cycled enough: it only gives the next level a
    start (two cycles when the estimate cannot stop it, else the estimate test)."""
    if (run.target == "residual" or not run.credible or not started) and run.cycles[lvl] >= 2:
        return True
    return (run.target == "discretisation" and run.credible and started
            and run.alg <= run.fraction * run.eta)


def _finest_test(run: _Run, problems: _LevelProblems, x: np.ndarray, r: np.ndarray,
                 last_true: float | None, started: bool):
    """The finest level's tests after a V-cycle: residual history and callback, a non-finite
    residual, and the residual rule or estimate test confirmed by a residual replacement (van der
    Vorst and Ye 2000). Returns ``(stop, r, last_true)``: ``r`` the replaced residual if any."""
    mg, e, lvl = run.mg, run.e, run.top
    res_norm = norm2(r)
    run.residuals.append(res_norm)
    if run.callback is not None:
        run.callback(scaled(x, e))
    if not math.isfinite(res_norm):
        run.reason = "non-finite"
        run.message = f"residual became {res_norm} at cycle {run.cycles[lvl]}"
        return True, r, last_true
    estimate_met = (run.target == "discretisation" and run.credible and started
                    and run.alg <= run.fraction * run.eta)
    if not (res_norm <= run.tol or estimate_met):
        return False, r, last_true
    # residual replacement before any verdict
    true_r = problems.level_rhs(lvl)
    true_r -= mg.matvec(x, lvl)
    true_norm = norm2(true_r)
    if true_norm <= run.tol or (estimate_met and true_norm <= 2.0 * res_norm + run.tol):
        run.stopped_by = ("residual rule" if res_norm <= run.tol and true_norm <= run.tol
                          else "discretisation-error estimate")
        run.reason, run.met = "converged", True
        return True, r, last_true
    if last_true is not None and not true_norm < last_true:
        run.reason = "stagnation"
        run.message = (f"the true residual {unscale(true_norm, e):.3e} did not decrease across a "
                       f"residual replacement (it was {unscale(last_true, e):.3e}); tolerance "
                       f"{run.prob.tolerance:.3e}: rounding errors limit the attainable accuracy")
        return True, r, last_true
    return False, true_r, true_norm


def _certify(run: _Run, fraction) -> SolveResult:
    """The result from the true residual recomputed at exit (:func:`finish`); a stop by the
    estimate test is certified when that residual agrees with the tracked one (factor 2)."""
    prob, e, top = run.prob, run.e, run.top
    run.alg, run.eta = unscale(run.alg, e), unscale(run.eta, e)   # energy norms in b's units
    run.etas = [unscale(v, e) for v in run.etas]
    if top:
        run.residuals = list(unscale_all(run.residuals, e))
    by_residual = run.stopped_by == "residual rule"
    res = finish(prob, iterations=run.cycles[top] if top else 0, residuals=run.residuals,
                 reason="converged" if by_residual else run.reason,
                 message=run.message, method="fmg", recursive_met=by_residual)
    if run.stopped_by == "discretisation-error estimate" and not res.converged:
        tracked = run.residuals[-1]
        if math.isfinite(res.true_residual) and res.true_residual <= 2.0 * tracked + prob.tolerance:
            res.converged, res.reason = True, "converged"
            res.message = (f"algebraic error bound {run.alg:.3e} <= {fraction:g} x estimated "
                           f"discretisation error {run.eta:.3e} (energy norm) after "
                           f"{run.cycles[top]} V-cycle(s) on the finest level; true residual "
                           f"{res.true_residual:.3e}")
        else:
            res.reason = "stagnation"
            res.message = (f"the estimate test passed but the true residual "
                           f"{res.true_residual:.3e} disagrees with the tracked {tracked:.3e}")
    return res


def _run_info(run: _Run, rho0: float, fraction, coarse: _CoarseData) -> dict:
    """FMG's facts for ``SolveResult.info`` (norms already in the units of b)."""
    return {
        "cycles_per_level": run.cycles, "rho": float(run.rho), "rho_setup": float(rho0),
        "discretisation_error_estimates": run.etas, "estimate_credible": run.credible,
        "algebraic_error_estimate": float(run.alg), "discretisation_error_estimate": float(run.eta),
        "target": run.target, "fraction": float(fraction), "stopped_by": run.stopped_by,
        "coarse_rhs": coarse.describe(),
    }
