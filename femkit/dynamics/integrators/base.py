"""Shared pieces of every time integrator: the step context, the stepper state, the base class.

Design
------
An integrator is a small frozen dataclass (its *options* are its fields) with two methods:

* ``start(system, x, v, t, dt, ctx) -> StepperState`` builds the state the integrator needs
  (multistep methods keep the previous position or a half-step velocity in ``state.aux``);
* ``step(system, state, dt, ctx) -> StepperState`` advances by one step and returns a *new*
  state (the input is never modified).

``state.x`` / ``state.v`` are always the positions and velocities at ``state.t`` (node-major
``(n, d)`` arrays), so energies and outputs read the same fields for every method.
Per-run caches (a factorised matrix, counters) live in :class:`StepContext`, never in the
integrator object, so one integrator instance can drive several runs.

Linear solves of the implicit methods go through :func:`solve_linear` / :func:`factorize_linear`,
which solve with the context's :class:`~femkit.solvers.SolverSpec` (``ctx.linear_solver``, the
one solver description of femkit; :meth:`SolverSpec.solve` is the one translator to
:func:`femkit.solvers.solve`) and restrict every system to ``system.free_dofs`` (pinned dofs are
eliminated).

Direct solves of a new matrix every step (Baraff-Witkin, Newton) reuse the ordering: the
first factorisation lets SuperLU order the matrix (symmetric mode, minimum degree on the actual
nonzero pattern); while later matrices have exactly the same pattern (compared by ``indptr`` and
``indices``, cached in ``ctx.cache["direct_ordering"]``), they are factorised pre-permuted with
that ordering and SuperLU's ``NATURAL`` column order, skipping the ordering step. A new pattern
(e.g. a planar cloth whose zero out-of-plane couplings fill in) is ordered afresh
(``ctx.stats["orderings"]``). Minimum degree on the node graph (dof triples kept together) was
tried and dropped: less fill but 1.3-1.5x the factorisation time on the cloths of the benchmark.
``ctx.stats`` accumulates the time split ``time_permute``, ``time_factorization`` and
``time_solve`` (seconds; assembly is what the integrator spends outside them).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...errors import InputError, SolverError, StabilityWarning
from ...solvers.norms import norm2
from ...solvers.spec import SolverSpec

__all__ = [
    "StepContext",
    "StepperState",
    "Integrator",
    "solve_linear",
    "factorize_linear",
    "uses_cholesky",
    "solve_cholesky",
    "solve_compiled",
    "restrict",
    "box_length",
    "check_iteration_options",
    "MATRIX_FREE_MESSAGE",
    "check_matrix_free",
    "check_matrix_free_options",
    "free_operator",
    "NonlinearConvergenceWarning",
    "note_unconverged",
]


@dataclass
class StepContext:
    """Linear-solver choice and per-run caches handed to every ``step``.

    Parameters
    ----------
    linear_solver : SolverSpec
        The linear solver of the implicit steps: method (``"direct"``, ``"cg"``, ``"pcg"``,
        ``"jacobi"``), preconditioner, stopping rule ``rtol``/``atol``/``maxiter`` and extra
        options (default: ``direct`` with ``rtol`` 1e-10).
    cache : dict
        Per-run caches (e.g. the fast mass-spring factorisation); filled by integrators.
    stats : dict
        Counters integrators report (``factorizations``, ``linear_solves``,
        ``newton_iterations`` list, ``linear_iterations``).
    """

    linear_solver: SolverSpec = field(default_factory=lambda: SolverSpec("direct"))
    cache: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)

    def count(self, key: str, n: int = 1) -> None:
        """Add ``n`` to counter ``key`` of :attr:`stats`."""
        self.stats[key] = self.stats.get(key, 0) + n

    def record(self, key: str, value) -> None:
        """Append ``value`` to the per-step list ``stats[key]`` (e.g. ``newton_iterations``)."""
        self.stats.setdefault(key, []).append(value)


@dataclass
class StepperState:
    """Positions ``x`` and velocities ``v`` (``(n, d)``) at time ``t``, plus method extras in ``aux``."""

    x: np.ndarray
    v: np.ndarray
    t: float
    aux: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Integrator:
    """Base class of all integrators (see the module docstring for the protocol).

    Class attributes every subclass sets: ``name``, ``order`` (global order of accuracy of the
    positions), ``implicit``, ``symplectic`` and ``stability_bound`` (the largest ``h * omega``
    for which the undamped oscillator stays bounded, ``inf`` for unconditionally stable methods;
    the critical step is ``stability_bound / omega_max``).
    """

    name = "integrator"
    order = 1
    implicit = False
    symplectic = False
    stability_bound = math.inf

    def start(self, system, x, v, t: float, dt: float, ctx: StepContext) -> StepperState:
        """Initial state: copies of ``x``, ``v`` with pinned velocities zeroed."""
        x = np.array(x, dtype=float, copy=True)
        v = np.array(v, dtype=float, copy=True)
        if x.shape != (system.n, system.dim) or v.shape != x.shape:
            raise InputError(
                f"{self.name}: x and v must have shape {(system.n, system.dim)}, "
                f"got {x.shape} and {v.shape}"
            )
        v[system.pinned] = 0.0
        if getattr(self, "matrix_free", False):  # refuse a solver that needs the matrix up front
            check_matrix_free(self.name, ctx)
        return StepperState(x, v, float(t))

    def step(self, system, state: StepperState, dt: float, ctx: StepContext) -> StepperState:
        raise NotImplementedError

    def dahlquist_amplification(self, z: complex) -> complex:
        """Amplification factor ``R(z)`` of the method on ``y' = lambda y``, ``z = h lambda``.

        Partitioned (symplectic) methods have no single-equation form and raise
        ``NotImplementedError``.
        """
        raise NotImplementedError(f"{self.name} has no first-order (Dahlquist) form")

    def describe(self) -> dict:
        """JSON-ready facts: name, order, implicit, symplectic, stability bound and options."""
        opts = {k: v for k, v in self.__dict__.items()}
        bound = self.stability_bound
        return {
            "name": self.name,
            "order": self.order,
            "implicit": self.implicit,
            "symplectic": self.symplectic,
            "stability_bound": None if math.isinf(bound) else float(bound),
            "options": opts,
        }


# ----------------------------------------------------------------------------- iterative steps
class NonlinearConvergenceWarning(StabilityWarning):
    """An iterative implicit step (``newton``, ``newmark``, ``variational_symplectic``) stopped
    at ``max_iterations`` without meeting its tolerance, so the step is not the method's exact
    step. A :class:`~femkit.errors.StabilityWarning` subclass, so scene runs record it in
    ``result.json``'s ``warnings``."""


def note_unconverged(name: str, ctx: StepContext, t: float, max_iterations: int, detail: str) -> None:
    """Count an unconverged step in ``ctx.stats["unconverged_steps"]`` and warn
    (:class:`NonlinearConvergenceWarning`) at the first one of the run (later ones are counted)."""
    ctx.count("unconverged_steps")
    if ctx.stats["unconverged_steps"] == 1:
        import warnings

        warnings.warn(NonlinearConvergenceWarning(
            f"{name}: the step ending at t = {t:.6g} stopped at max_iterations = {max_iterations} "
            f"without meeting its tolerance ({detail}); later unconverged steps are counted in "
            "stats['unconverged_steps']. Raise max_iterations or reduce dt"), stacklevel=3)


def box_length(x: np.ndarray) -> float:
    """Bounding-box diagonal of ``x`` (1 when it is 0): the length ``L`` of the stopping rules
    ``||dx||_inf <= tol * L`` of the iterative implicit steps.

    >>> box_length(np.array([[0.0, 0.0], [3.0, 4.0]]))
    5.0
    """
    return float(np.linalg.norm(np.ptp(x, axis=0))) or 1.0


def check_iteration_options(name: str, max_iterations: int, tol: float | None, *,
                            option: str = "max_iterations") -> None:
    """Raise :class:`~femkit.errors.InputError` unless ``max_iterations >= 1`` and ``tol > 0``
    (``tol=None``: no tolerance, sweeps only); ``option`` is the option's name in messages."""
    if int(max_iterations) < 1 or (tol is not None and not tol > 0):
        raise InputError(f"{name}: need {option} >= 1 and tol > 0, "
                         f"got {option}={max_iterations!r}, tol={tol!r}")


# ----------------------------------------------------------------------------- linear algebra
def restrict(A, free):
    """``A[free][:, free]`` for a sparse matrix (CSR out)."""
    A = A.tocsr()
    return A[free][:, free].tocsr()


class PermutedFactor:
    """The factor of ``A[p][:, p]`` used as a solver for ``A``: ``solve(b) = A^-1 b``."""

    def __init__(self, factor, perm: np.ndarray):
        self.factor = factor
        self.perm = perm
        self.shape = factor.shape
        self.info = factor.info

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for ``b`` of shape ``(n,)`` or ``(n, k)``."""
        y = self.factor.solve(np.asarray(b, dtype=float)[self.perm])
        x = np.empty_like(y)
        x[self.perm] = y
        return x

    __call__ = solve
    symmetric = property(lambda self: self.factor.symmetric)


def _add_time(ctx: StepContext, key: str, seconds: float) -> None:
    ctx.stats[key] = ctx.stats.get(key, 0.0) + seconds


def solve_linear(A, b: np.ndarray, ctx: StepContext, x0: np.ndarray | None = None, *,
                 system=None, reuse_key: str | None = None,
                 diagonal: np.ndarray | None = None) -> np.ndarray:
    """Solve ``A x = b`` with the method named in ``ctx`` through ``femkit.solvers``.

    ``A`` may be a ``scipy.sparse.linalg.LinearOperator`` (matrix-free, :func:`free_operator`):
    then ``ctx`` must name ``cg`` or ``pcg`` with preconditioner ``none`` or ``jacobi``
    (:func:`check_matrix_free`) and ``diagonal`` (the operator's diagonal) builds the Jacobi
    preconditioner.

    With a ``direct`` solver and the ``system`` (which marks a matrix refactorised every
    step), the SuperLU ordering is reused while the pattern of ``A`` stays the same (module
    docstring); the result must meet the direct solver's rule
    ``||b - A x|| <= max(rtol ||b||, atol)``.

    ``reuse_key`` (direct only): keep the factorisation in ``ctx.cache[reuse_key]`` and solve
    later systems (a slowly changing matrix: Newton iterations and steps) by PCG preconditioned
    with that older factor, to the same rule ``||b - A x|| <= max(rtol ||b||, atol)`` on the
    true residual. The factor is renewed when a PCG solve costs more than the average cost per
    solve since the factorisation (factorisation included), and at once when PCG misses the
    tolerance within ``REUSE_MAX_ITERATIONS`` iterations (or breaks down). The answer is the
    solution of ``A x = b`` to ``rtol`` either way; only the cost changes.

    Raises :class:`~femkit.errors.SolverError` when an iterative method does not converge (or a
    direct solve misses the residual rule): an implicit step never continues from an
    unconverged solve.
    """
    from scipy.sparse.linalg import LinearOperator

    spec = ctx.linear_solver
    if isinstance(A, LinearOperator):
        check_matrix_free("matrix-free solve", ctx)
        if spec.method == "pcg" and spec.preconditioner == "jacobi":
            if diagonal is None:
                raise InputError("matrix-free pcg with jacobi needs the operator's diagonal")
            spec = replace(spec, preconditioner_options={**spec.preconditioner_options,
                                                         "diagonal": diagonal})
    elif reuse_key is not None and spec.backend != "femkit":
        raise InputError(f"reuse_factorization keeps femkit's SuperLU factor; linear_solver."
                         f"backend {spec.backend!r} is not supported with it (use backend: femkit)")
    elif (system is not None and spec.method == "direct" and not spec.options
          and spec.backend == "femkit"):
        if reuse_key is not None:
            return _solve_reusing_factor(A, b, ctx, reuse_key, x0)
        return _solve_direct_reusing_ordering(A, b, ctx)

    ctx.count("linear_solves")
    res = spec.solve(A, b, x0)
    ctx.count("linear_iterations", int(res.iterations))
    if not res.converged:
        raise SolverError(
            f"linear solve ({spec.method}/{spec.preconditioner}) did not converge: {res.reason}; "
            f"relative residual {res.relative_residual:.3e} after {res.iterations} iterations"
        )
    return np.asarray(res.x, dtype=float)


def _ordered_factor(A, ctx: StepContext):
    """Factor of csr ``A``, reusing the cached SuperLU ordering when the pattern is unchanged."""
    from ...solvers import factorize

    cached = ctx.cache.get("direct_ordering")
    if (cached is not None and cached[0].shape == A.indptr.shape and cached[1].shape == A.indices.shape
            and np.array_equal(cached[0], A.indptr) and np.array_equal(cached[1], A.indices)):
        perm = cached[2]
        t0 = time.perf_counter()
        Ap = A[perm][:, perm]
        t1 = time.perf_counter()
        factor = PermutedFactor(factorize(Ap, permc_spec="NATURAL"), perm)
        _add_time(ctx, "time_permute", t1 - t0)
        _add_time(ctx, "time_factorization", time.perf_counter() - t1)
        return factor
    t0 = time.perf_counter()
    factor = factorize(A)
    _add_time(ctx, "time_factorization", time.perf_counter() - t0)
    if factor.symmetric:  # symmetric mode: rows and columns share SuperLU's ordering
        ctx.cache["direct_ordering"] = (A.indptr.copy(), A.indices.copy(), np.argsort(factor.perm_c))
        ctx.count("orderings")
    return factor


REUSE_MAX_ITERATIONS = 50
"""Hard cap on the PCG iterations with a reused (older) factorisation before refactorising."""


@dataclass
class _ReusedFactor:
    """A kept factorisation and what it has cost so far (seconds)."""

    factor: Any
    factor_time: float
    solve_time: float = 0.0
    solves: int = 1


def _solve_reusing_factor(A, b: np.ndarray, ctx: StepContext, key: str, x0=None,
                          direct=None) -> np.ndarray:
    """PCG with the kept factor; the renewal rule drops the factor once one PCG solve costs more
    than the average cost per solve since it was made (factorisation included), so the next
    solve refactorises; a PCG solve that misses the tolerance within the cap refactorises now."""
    import scipy.sparse as sp

    kept = ctx.cache.get(key)
    b = np.asarray(b, dtype=float)
    if kept is not None and tuple(kept.factor.shape) == A.shape and b.any():
        t0 = time.perf_counter()
        spec = replace(ctx.linear_solver, method="pcg", preconditioner=kept.factor,
                       maxiter=REUSE_MAX_ITERATIONS, options={"check_symmetry": False})
        res = spec.solve(sp.csr_matrix(A), b, x0)
        spent = time.perf_counter() - t0
        _add_time(ctx, "time_pcg", spent)
        ctx.count("linear_solves")
        ctx.count("linear_iterations", int(res.iterations))
        if res.converged:
            kept.solves += 1
            kept.solve_time += spent
            if spent * kept.solves > kept.factor_time + kept.solve_time:
                ctx.cache.pop(key, None)  # marginal cost above the average: refactorise next
            return np.asarray(res.x, dtype=float)
        ctx.count("refactorizations")
    if direct is not None:  # e.g. the Cholesky refactorisation of the compiled path
        return direct(A, b, ctx, key)
    return _solve_direct_reusing_ordering(A, b, ctx, keep=key)


def _solve_direct_reusing_ordering(A, b: np.ndarray, ctx: StepContext,
                                   keep: str | None = None) -> np.ndarray:
    import scipy.sparse as sp

    ctx.count("linear_solves")
    b = np.asarray(b, dtype=float)
    if not b.any():   # b = 0 decided by its entries, not by a norm that may underflow
        return np.zeros_like(b)
    bnorm = norm2(b)
    A = sp.csr_matrix(A)
    t_factor = time.perf_counter()
    factor = _ordered_factor(A, ctx)
    ctx.count("factorizations")
    if keep is not None:  # a symmetric-mode (SPD) factor preconditions later solves
        if factor.symmetric:
            ctx.cache[keep] = _ReusedFactor(factor, time.perf_counter() - t_factor)
        else:
            ctx.cache.pop(keep, None)
    return _checked_solve(factor, A, b, bnorm, ctx, "direct")


def _checked_solve(factor, A, b: np.ndarray, bnorm: float, ctx: StepContext, name: str) -> np.ndarray:
    """``factor.solve(b)`` (timed as ``time_solve``) under the direct solvers' residual rule
    ``||b - A x|| <= max(rtol ||b||, atol)``; :class:`~femkit.errors.SolverError` otherwise."""
    t0 = time.perf_counter()
    x = factor.solve(b)
    _add_time(ctx, "time_solve", time.perf_counter() - t0)
    res = norm2(b - A @ x)
    rtol, atol = ctx.linear_solver.rtol, ctx.linear_solver.atol
    if not (np.isfinite(res) and res <= max(rtol * bnorm, atol)):
        raise SolverError(
            f"linear solve ({name}) missed the residual rule: relative residual {res / bnorm:.3e} "
            f"> rtol {rtol:.1e}; the matrix is numerically singular or very ill-conditioned")
    return x


def factorize_linear(A, ctx: StepContext):
    """Factorise a sparse SPD matrix once for repeated solves; returns an object with ``.solve(b)``.

    ``b`` may be ``(n,)`` or ``(n, k)`` (several right-hand sides in one call). With
    ``ctx.linear_solver.method == "cholesky"`` the factor is CHOLMOD's (:func:`femkit.solvers.factorize_spd`;
    :class:`~femkit.errors.NotSPDError` if ``A`` is not SPD), otherwise SuperLU's.
    """
    from ...solvers import factorize

    if ctx.linear_solver.backend != "femkit":
        raise InputError(f"a factorisation kept for the whole run uses femkit's SuperLU; "
                         f"linear_solver.backend {ctx.linear_solver.backend!r} is not supported "
                         f"here (use backend: femkit)")
    ctx.count("factorizations")
    if ctx.linear_solver.method == "cholesky":
        # factorised once, solved many times: the least fill (nested dissection) and the
        # simplicial solve, the faster one on these patterns (femkit.solvers.cholesky.MODES)
        from ...solvers import factorize_spd

        engine = cholesky_engine(ctx)
        return factorize_spd(A, ordering="nesdis", engine=engine,
                             mode="simplicial" if engine == "cholmod" else "supernodal")
    return factorize(A)


def cholesky_engine(ctx: StepContext) -> str:
    """The factorisation library of ``linear_solver: {method: cholesky, options: {engine}}``:
    ``cholmod`` (default) or ``pardiso`` (:data:`femkit.solvers.cholesky.ENGINES`)."""
    return ctx.linear_solver.options.get("engine", "cholmod")


def uses_cholesky(ctx: StepContext, integrator) -> bool:
    """Whether a step takes the compiled path: ``ctx.linear_solver.method == "cholesky"`` (assembled, not
    matrix-free)."""
    return ctx.linear_solver.method == "cholesky" and not getattr(integrator, "matrix_free", False)


def solve_compiled(A, b: np.ndarray, ctx: StepContext, pattern, reuse_key: str | None = None) -> np.ndarray:
    """:func:`solve_cholesky`, or with ``reuse_key`` (``reuse_factorization=True``) PCG
    preconditioned by the kept (older) Cholesky factor under the renewal rule of
    :func:`solve_linear`, the refactorisation being :func:`solve_cholesky`'s."""
    if reuse_key is None:
        return solve_cholesky(A, b, ctx, pattern)
    return _solve_reusing_factor(
        A, b, ctx, reuse_key,
        direct=lambda A, b, ctx, keep: solve_cholesky(A, b, ctx, pattern, keep=keep))


def solve_cholesky(A, b: np.ndarray, ctx: StepContext, pattern, key: str = "cholesky_factor",
                   keep: str | None = None) -> np.ndarray:
    """Solve ``A x = b`` for an SPD ``A`` assembled into the fixed ``pattern`` (a
    :class:`~femkit.dynamics.kernels.assembly.FreePattern`, the same object every step): the
    factor kept in ``ctx.cache[key]`` is refactorised in place on its symbolic analysis while
    the pattern object is the same and no coordinate pair has become nonzero that was all
    zero before (those are left out of the factor: see the comment in the code; no hashing),
    and factorised afresh (analysis from the pattern cache of :mod:`femkit.solvers.cholesky`)
    otherwise. Counts ``factorizations`` and ``symbolic_reuses``, times ``time_factorization``
    and ``time_solve``, and applies the direct solver's residual rule
    ``||b - A x|| <= max(rtol ||b||, atol)`` (:class:`~femkit.errors.SolverError` otherwise).
    """
    import scipy.sparse as sp

    from ...solvers import factorize_spd

    ctx.count("linear_solves")
    b = np.asarray(b, dtype=float)
    if not b.any():
        return np.zeros_like(b)
    bnorm = norm2(b)
    kept = ctx.cache.get(key)
    t0 = time.perf_counter()
    # Coordinate pairs (x-y, y-z ...) whose couplings have all been exactly zero so far (the
    # out-of-plane couplings of a planar cloth) are left out of the factor, which exploits them;
    # all entries of a pair enter once one of them is nonzero, and the same-coordinate pairs
    # always (the clamp zeroes and restores them spring by spring). So the analysed pattern
    # changes only when the geometry leaves its plane, and every other step refactorises in place.
    d = pattern.dim
    seen = np.bincount(pattern.coordinate_pair[A.data != 0.0], minlength=d * d) > 0
    seen[np.arange(d) * (d + 1)] = True
    if kept is not None and kept[0] is pattern:
        seen |= kept[1]
    if kept is not None and kept[0] is pattern and np.array_equal(seen, kept[1]):
        mask = kept[2]
        Ac = sp.csr_matrix((A.data[mask], kept[4], kept[3]), shape=A.shape)
        factor = kept[5].refactor(Ac)
    else:
        mask = seen[pattern.coordinate_pair]
        counts = np.concatenate([[0], np.cumsum(mask)])
        Ac = sp.csr_matrix((A.data[mask], A.indices[mask], counts[A.indptr]), shape=A.shape)
        factor = factorize_spd(Ac, engine=cholesky_engine(ctx), check_symmetry=False)
        ctx.cache[key] = (pattern, seen, mask, Ac.indptr, Ac.indices, factor)
    ctx.count("factorizations")
    if factor.info["symbolic_reused"]:
        ctx.count("symbolic_reuses")
    spent = time.perf_counter() - t0
    _add_time(ctx, "time_factorization", spent)
    if keep is not None:  # preconditions later solves (reuse_factorization)
        ctx.cache[keep] = _ReusedFactor(factor, spent)
    return _checked_solve(factor, Ac, b, bnorm, ctx, "cholesky")


# ----------------------------------------------------------------------------- matrix-free
MATRIX_FREE_MESSAGE = "matrix-free needs an iterative solver: cg or pcg (jacobi)"
"""The reason given when ``matrix_free`` meets a solver or preconditioner that needs the matrix."""

MATRIX_FREE_SOLVERS = {"cg": ("none",), "pcg": ("none", "jacobi")}
"""Solvers (and their preconditioners) that need only products ``A d`` and ``diag(A)``."""


def check_matrix_free(name: str, ctx: StepContext) -> None:
    """Raise :class:`~femkit.errors.InputError` unless ``ctx`` names a solver that works from
    products alone: ``cg``, or ``pcg`` with preconditioner ``none``/``jacobi`` (``direct``,
    ``jacobi`` iteration, ``ic0`` and ``amg`` need the assembled matrix).

    >>> check_matrix_free("implicit_euler", StepContext(SolverSpec("pcg", "jacobi")))
    >>> check_matrix_free("implicit_euler", StepContext(SolverSpec("direct")))
    Traceback (most recent call last):
    ...
    femkit.errors.InputError: implicit_euler: matrix-free needs an iterative solver: cg or pcg (jacobi); got linear solver 'direct'
    """
    spec = ctx.linear_solver
    if spec.backend != "femkit":
        raise InputError(f"{name}: matrix-free solves run in femkit's own solvers; linear_solver."
                         f"backend {spec.backend!r} needs the assembled matrix")
    allowed = MATRIX_FREE_SOLVERS.get(spec.method)
    if allowed is None:
        raise InputError(f"{name}: {MATRIX_FREE_MESSAGE}; got linear solver {spec.method!r}")
    pc = spec.preconditioner if spec.method == "pcg" else "none"
    if pc not in allowed:
        raise InputError(f"{name}: {MATRIX_FREE_MESSAGE}; preconditioner {pc!r} needs the "
                         f"assembled matrix")


def check_matrix_free_options(name: str, matrix_free: bool, reuse_factorization: bool) -> None:
    """Raise :class:`~femkit.errors.InputError` when both options are on (nothing to factorise)."""
    if matrix_free and reuse_factorization:
        raise InputError(f"{name}: matrix_free and reuse_factorization exclude each other "
                         "(there is no matrix to factorise)")


def free_operator(product, free: np.ndarray, ndof: int):
    """The ``LinearOperator`` ``z -> (A e)[free]`` with ``e`` = ``z`` on the ``free`` dofs
    and 0 on the pinned ones, i.e. ``A[free][:, free]`` applied without forming it.

    ``product`` maps a flat ``(ndof,)`` vector to ``A e`` (flat or ``(n, d)``).

    >>> op = free_operator(lambda e: 2.0 * e, np.array([0, 2]), 3)
    >>> op.matvec(np.array([1.0, 5.0])).tolist()
    [2.0, 10.0]
    """
    from scipy.sparse.linalg import LinearOperator

    nf = len(free)

    def matvec(z):
        e = np.zeros(ndof)
        e[free] = np.ravel(z)
        return np.asarray(product(e)).reshape(-1)[free]

    return LinearOperator((nf, nf), matvec=matvec, rmatvec=matvec, dtype=np.float64)
