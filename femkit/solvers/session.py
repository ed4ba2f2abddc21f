"""A linear-solve session: one solver spec, a sequence of solves, and everything worth keeping
between them.

Whoever solves more than once with one :class:`~femkit.solvers.SolverSpec` (the implicit
integrators every step, the Poisson pipeline, a study's sweep) asks a :class:`LinearSession`,
created from the spec (:meth:`SolverSpec.session`), instead of branching on solver names. The
session owns:

* the one translator of a spec into :func:`femkit.solvers.solve` (:meth:`LinearSession.run`,
  the PETSc route included: ``backend: petsc`` passes through to
  :data:`femkit.solvers.registry.BACKENDS`);
* **matrix-free solves**: a ``LinearOperator`` is accepted by the methods the registry declares
  ``matrix_free`` (:func:`check_matrix_free`), a Jacobi preconditioner built from the
  operator's diagonal;
* **ordering reuse** (``direct``, :meth:`LinearSession.solve` with ``refactor=True``): a matrix
  refactorised every solve (Baraff-Witkin, Newton) keeps SuperLU's ordering while the pattern
  (``indptr``, ``indices``) stays the same, and is factorised pre-permuted with ``NATURAL``
  column order (:class:`~femkit.solvers.factor.PermutedFactor`); a new pattern is ordered
  afresh (``stats["orderings"]``). Minimum degree on the node graph (dof triples kept
  together) was tried and dropped: less fill but 1.3-1.5x the factorisation time on the cloths
  of the benchmark;
* **symbolic reuse** (``cholesky``, :meth:`LinearSession.solve_on_pattern`): a matrix assembled
  into one fixed pattern is refactorised in place on its analysis
  (:meth:`~femkit.solvers.factor.Factor.refactor`);
* **preconditioner reuse** (``keep=``): a kept factorisation preconditions the PCG solves of
  later, slowly changing matrices, renewed by a cost rule (:meth:`LinearSession.solve`);
* a **factor kept for the whole run** (:meth:`LinearSession.factorize`), and its iterative
  counterpart, a **preconditioner kept for a fixed matrix** (:meth:`LinearSession.solve_kept`:
  the AMG hierarchy, IC(0) factor or GMG hierarchy of one matrix built once under a key and
  reused by every later PCG solve with that same matrix, as the time steps of a fixed ``dt``
  do; a new matrix under the key is set up afresh, ``stats["preconditioner_setups"]``).

Counters and times accumulate in :attr:`LinearSession.stats`: ``linear_solves``,
``linear_iterations``, ``factorizations``, ``orderings``, ``symbolic_reuses``,
``refactorizations``, ``preconditioner_setups``, ``time_permute``, ``time_factorization``,
``time_solve``, ``time_pcg``, ``time_preconditioner_setup`` (seconds).

Every answer meets the stopping rule ``||b - A x|| <= max(rtol ||b||, atol)`` of the spec, the
direct ones on the true residual; otherwise :class:`~femkit.errors.SolverError`.

>>> import numpy as np, scipy.sparse as sp
>>> from femkit.solvers import SolverSpec
>>> s = SolverSpec("direct").session()
>>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(6, 6), format="csr")
>>> for k in range(3):
...     x = s.solve((1.0 + k) * A, np.ones(6), refactor=True)
>>> s.stats["factorizations"], s.stats["orderings"]
(3, 1)
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from ..errors import InputError, SolverError
from .core import defaults
from .factor import Factor, PermutedFactor
from .core.norms import norm2
from .core.pairing import PRECONDITIONED_METHOD
from .registry import PRECONDITIONERS, SOLVERS, matrix_free_names, traits

__all__ = ["LinearSession", "check_matrix_free", "matrix_free_message", "MATRIX_FREE_MESSAGE",
           "REUSE_MAX_ITERATIONS"]

REUSE_MAX_ITERATIONS = 50
"""Hard cap on the PCG iterations with a reused (older) factorisation before refactorising."""

REFINEMENT_STEPS = 3
"""Iterative-refinement steps of a direct answer that misses the residual rule."""


def matrix_free_message() -> str:
    """Why a solver is refused for an operator that is never assembled, naming the methods
    and preconditioners the registry declares ``matrix_free``."""
    methods, pcs = matrix_free_names()
    return f"matrix-free needs an iterative solver: {' or '.join(methods)} ({', '.join(pcs)})"


MATRIX_FREE_MESSAGE = matrix_free_message()
"""The reason given when ``matrix_free`` meets a solver or preconditioner that needs the matrix."""


def check_matrix_free(name: str, spec) -> None:
    """Raise :class:`~femkit.errors.InputError` (starting with ``name``) unless ``spec`` names
    a solver that works from products alone: a method and preconditioner the registry declares
    ``matrix_free`` (``cg``, or ``pcg`` with ``none``/``jacobi``), on femkit's own backend.

    >>> from femkit.solvers import SolverSpec
    >>> check_matrix_free("implicit_euler", SolverSpec("pcg", "jacobi"))
    >>> check_matrix_free("implicit_euler", SolverSpec("direct"))
    Traceback (most recent call last):
    ...
    femkit.errors.InputError: implicit_euler: matrix-free needs an iterative solver: cg or pcg (jacobi); got linear solver 'direct'
    """
    if spec.backend != "femkit":
        raise InputError(f"{name}: matrix-free solves run in femkit's own solvers; linear_solver."
                         f"backend {spec.backend!r} needs the assembled matrix")
    if not traits(SOLVERS, spec.method).matrix_free:
        raise InputError(f"{name}: {MATRIX_FREE_MESSAGE}; got linear solver {spec.method!r}")
    pc = spec.preconditioner if spec.method == PRECONDITIONED_METHOD else "none"
    if not traits(PRECONDITIONERS, pc).matrix_free:
        raise InputError(f"{name}: {MATRIX_FREE_MESSAGE}; preconditioner {pc!r} needs the "
                         f"assembled matrix")


def symmetric_permutation(A, perm: np.ndarray):
    """``A[perm][:, perm]`` of a CSR matrix by two gathers (new row ``r`` is old row
    ``perm[r]``, old column ``c`` becomes ``inv[c]``): the same entries at the same places as
    SciPy's fancy indexing, without its ~8 intermediate sparse matrices (a small system's
    refactorisation spent a quarter of its time there). Row entries keep their stored order
    (unsorted columns), as the factorisation's CSC conversion sorts them."""
    import scipy.sparse as sp

    n = A.shape[0]
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    lengths = np.diff(A.indptr)
    indptr = np.zeros(n + 1, dtype=A.indptr.dtype)
    np.cumsum(lengths[perm], out=indptr[1:])
    order = np.argsort(np.repeat(inv, lengths), kind="stable")   # entries grouped by new row
    indices = inv[A.indices[order]].astype(A.indices.dtype, copy=False)
    return sp.csr_matrix((A.data[order], indices, indptr), shape=A.shape)


@dataclass
class _Kept:
    """A kept factorisation (preconditioner of later solves) and what it has cost (seconds)."""

    factor: Any
    factor_time: float
    solve_time: float = 0.0
    solves: int = 1


class LinearSession:
    """Solves with one :class:`~femkit.solvers.SolverSpec`, reusing what a sequence of solves
    with a fixed sparsity pattern can share (module docstring).

    Parameters
    ----------
    spec : SolverSpec
        Method, preconditioner, stopping rule, options, backend.
    stats : dict, optional
        Where counters and times accumulate (shared with the caller's, e.g. an integrator
        run's ``ctx.stats``); a new dict by default.
    """

    def __init__(self, spec, stats: dict | None = None):
        self.spec = spec
        self.stats = {} if stats is None else stats
        self._ordering: tuple | None = None       # (indptr, indices, perm) of the last pattern
        self._kept: dict[str, _Kept] = {}          # preconditioner reuse, by caller's key
        self._pattern: dict[str, tuple] = {}       # symbolic reuse on a fixed pattern, by key
        self._kept_pc: dict[Any, tuple] = {}       # (matrix, preconditioner) kept, by key

    # ------------------------------------------------------------------ facts and counters
    @property
    def factors_on_pattern(self) -> bool:
        """Whether assembled solves go through :meth:`solve_on_pattern` (``cholesky``: one
        symbolic analysis refactorised in place for a fixed pattern)."""
        return self.spec.method == "cholesky"

    @property
    def engine(self) -> str:
        """The factorisation library of ``cholesky`` (``options: {engine}``): ``cholmod``
        (default) or ``pardiso`` (:data:`femkit.solvers.cholesky.ENGINES`)."""
        return self.spec.options.get("engine", defaults.DEFAULT_ENGINE)

    def _count(self, key: str, n: int = 1) -> None:
        self.stats[key] = self.stats.get(key, 0) + n

    def _time(self, key: str, seconds: float) -> None:
        self.stats[key] = self.stats.get(key, 0.0) + seconds

    def _femkit_only(self, what: str) -> None:
        if self.spec.backend != "femkit":
            raise InputError(f"{what} keeps femkit's SuperLU factor; linear_solver.backend "
                             f"{self.spec.backend!r} is not supported with it (use backend: femkit)")

    # ------------------------------------------------------------------ one solve
    def run(self, A, b, x0=None, *, callback: Callable | None = None, spec=None, **overrides):
        """One solve with the spec (or ``spec``), returning the
        :class:`~femkit.solvers.SolveResult`: the one translator to :func:`femkit.solvers.solve`.

        ``overrides`` (e.g. ``atol``) replace the spec's stopping-rule values; ``options=`` /
        ``preconditioner_options=`` add run-time objects to the spec's own (the mesh hierarchy
        of geometric multigrid).
        """
        from .registry import solve

        spec = self.spec if spec is None else spec
        pc_options = {**spec.preconditioner_options, **overrides.pop("preconditioner_options", {})}
        options = {**spec.options, **overrides.pop("options", {})}
        kw = dict(rtol=spec.rtol, atol=spec.atol, maxiter=spec.maxiter)
        kw.update(overrides)
        if spec.backend != "femkit":
            kw.update(backend=spec.backend, petsc_options=spec.petsc_options or None)
        return solve(A, b, x0, method=spec.method,
                     preconditioner=spec.preconditioner if spec.method == PRECONDITIONED_METHOD else None,
                     callback=callback, preconditioner_options=pc_options or None,
                     **kw, **options)

    def solve(self, A, b: np.ndarray, x0: np.ndarray | None = None, *, refactor: bool = False,
              keep: str | None = None, diagonal: np.ndarray | None = None,
              accept: float | None = None) -> np.ndarray:
        """Solve ``A x = b`` and return ``x``; :class:`~femkit.errors.SolverError` when the
        solve does not meet the stopping rule (a caller never continues from it).

        Parameters
        ----------
        A : sparse matrix or LinearOperator
            A ``LinearOperator`` (matrix-free) needs a ``matrix_free`` method
            (:func:`check_matrix_free`); ``diagonal`` (the operator's diagonal) then builds the
            Jacobi preconditioner.
        refactor : bool
            ``A`` is a new matrix of (usually) the same pattern as the last one: with
            ``direct`` (femkit's backend, no options) SuperLU's ordering is reused while the
            pattern stays the same.
        keep : str, optional
            Keep the factorisation under this key and solve later systems (a slowly changing
            matrix: Newton iterations and steps) by PCG preconditioned with that older factor,
            to the same rule on the true residual. The factor is renewed when a PCG solve costs
            more than the average cost per solve since the factorisation (factorisation
            included), and at once when PCG misses the tolerance within
            :data:`REUSE_MAX_ITERATIONS` iterations (or breaks down). ``direct`` only.
        accept : float, optional
            The relative residual the caller can use when the spec's ``rtol`` is out of reach
            (a Newton direction needs no more: inexact Newton, Dembo, Eisenstat & Steihaug 1982,
            "Inexact Newton methods", SIAM J. Numer. Anal. 19(2)); such an answer is counted in
            ``stats["inexact_solves"]``. A direct answer is first refined
            (:meth:`_checked_solve`); by default the rule is ``rtol``'s alone.
        """
        from scipy.sparse.linalg import LinearOperator

        spec = self.spec
        if isinstance(A, LinearOperator):
            check_matrix_free("matrix-free solve", spec)
            if spec.method == PRECONDITIONED_METHOD and spec.preconditioner == "jacobi":
                if diagonal is None:
                    raise InputError("matrix-free pcg with jacobi needs the operator's diagonal")
                spec = replace(spec, preconditioner_options={**spec.preconditioner_options,
                                                             "diagonal": diagonal})
        elif keep is not None and spec.backend != "femkit":
            self._femkit_only("reuse_factorization")
        elif refactor and spec.method == "direct" and not spec.options and spec.backend == "femkit":
            if keep is not None:
                return self._solve_reusing_factor(A, b, keep, x0, accept=accept)
            return self._solve_direct(A, b, accept=accept)
        return self._counted_run(A, b, x0, spec, f"{spec.method}/{spec.preconditioner}", accept)

    def _counted_run(self, A, b, x0, spec, label: str, accept: float | None = None) -> np.ndarray:
        """:meth:`run` counted in ``stats``, its ``x`` if it met the stopping rule (or the
        caller's ``accept``, counted as ``inexact_solves``), else
        :class:`~femkit.errors.SolverError` naming ``label``."""
        self._count("linear_solves")
        res = self.run(A, b, x0, spec=spec)
        self._count("linear_iterations", int(res.iterations))
        if not res.converged and accept is not None and np.isfinite(res.x).all() \
                and res.relative_residual <= accept:
            self._count("inexact_solves")
        elif not res.converged:
            raise SolverError(
                f"linear solve ({label}) did not converge: {res.reason}; "
                f"relative residual {res.relative_residual:.3e} after {res.iterations} iterations")
        return np.asarray(res.x, dtype=float)

    def solve_kept(self, A, b: np.ndarray, x0: np.ndarray | None = None, *, key: Any = "kept",
                   preconditioner_options: dict | None = None) -> np.ndarray:
        """Solve ``A x = b`` with the spec's iterative method, ``pcg``'s preconditioner built
        once for the matrix ``A`` under ``key`` and kept for every later solve with the same
        matrix object (the step matrix of a fixed ``dt``): the iterative counterpart of
        :meth:`factorize`. A different matrix under ``key`` is set up afresh and replaces it.
        Methods without a preconditioner (``cg``, ``jacobi``, ``fmg``) solve as :meth:`solve`.

        Parameters
        ----------
        A : sparse matrix
            Kept by the caller unchanged while it is reused (identity decides reuse).
        x0 : array, optional
            Initial guess (warm start).
        key : hashable
            Which kept preconditioner (one per distinct matrix of the caller).
        preconditioner_options : dict, optional
            Run-time objects added to the spec's (the mesh hierarchy of ``gmg``).
        """
        spec = self.spec
        if spec.method != PRECONDITIONED_METHOD or spec.backend != "femkit":
            return self.solve(A, b, x0)
        kept = self._kept_pc.get(key)
        if kept is None or kept[0] is not A:
            opts = {**spec.preconditioner_options, **(preconditioner_options or {})}
            t0 = time.perf_counter()
            pc = PRECONDITIONERS.get(spec.preconditioner)(A, **opts)
            self._time("time_preconditioner_setup", time.perf_counter() - t0)
            self._count("preconditioner_setups")
            kept = self._kept_pc[key] = (A, pc)
            checked = {}                           # the first solve checks A's symmetry ...
        else:
            checked = {"check_symmetry": False}    # ... which later solves of A need not repeat
        return self._counted_run(A, b, x0, replace(spec, preconditioner=kept[1],
                                                   preconditioner_options={},
                                                   options={**spec.options, **checked}),
                                 f"pcg/{spec.preconditioner}, kept")

    # ------------------------------------------------------------------ kept factors
    def factorize(self, A) -> Factor:
        """Factorise a sparse SPD matrix once for the whole run (``solve(b)`` with ``b`` of shape
        ``(n,)`` or ``(n, k)``). With ``cholesky`` the factor is the engine's (nested
        dissection; CHOLMOD's simplicial mode, the faster solves on these patterns;
        :class:`~femkit.errors.NotSPDError` if ``A`` is not SPD), otherwise SuperLU's."""
        from .kept_factor import factorize_kept

        if self.spec.backend != "femkit":
            raise InputError(f"a factorisation kept for the whole run uses femkit's SuperLU; "
                             f"linear_solver.backend {self.spec.backend!r} is not supported "
                             f"here (use backend: femkit)")
        self._count("factorizations")
        cholesky = self.spec.method == "cholesky"
        return factorize_kept(A, method=self.spec.method, engine=self.engine if cholesky else None)

    def _ordered_factor(self, A) -> Factor:
        """Factor of csr ``A``, reusing the kept SuperLU ordering when the pattern is unchanged."""
        from .direct import factorize

        kept = self._ordering
        if (kept is not None and kept[0].shape == A.indptr.shape and kept[1].shape == A.indices.shape
                and np.array_equal(kept[0], A.indptr) and np.array_equal(kept[1], A.indices)):
            perm = kept[2]
            t0 = time.perf_counter()
            Ap = symmetric_permutation(A, perm)
            t1 = time.perf_counter()
            factor = PermutedFactor(factorize(Ap, permc_spec="NATURAL"), perm)
            self._time("time_permute", t1 - t0)
            self._time("time_factorization", time.perf_counter() - t1)
            return factor
        t0 = time.perf_counter()
        factor = factorize(A)
        self._time("time_factorization", time.perf_counter() - t0)
        if factor.symmetric:  # symmetric mode: rows and columns share SuperLU's ordering
            self._ordering = (A.indptr.copy(), A.indices.copy(), np.argsort(factor.perm_c))
            self._count("orderings")
        return factor

    def _solve_direct(self, A, b: np.ndarray, keep: str | None = None,
                      accept: float | None = None) -> np.ndarray:
        import scipy.sparse as sp

        self._count("linear_solves")
        b = np.asarray(b, dtype=float)
        if not b.any():   # b = 0 decided by its entries, not by a norm that may underflow
            return np.zeros_like(b)
        bnorm = norm2(b)
        A = sp.csr_matrix(A)
        t_factor = time.perf_counter()
        factor = self._ordered_factor(A)
        self._count("factorizations")
        if keep is not None:  # a symmetric-mode (SPD) factor preconditions later solves
            if factor.symmetric:
                self._kept[keep] = _Kept(factor, time.perf_counter() - t_factor)
            else:
                self._kept.pop(keep, None)
        return self._checked_solve(factor, A, b, bnorm, "direct", accept)

    def _solve_reusing_factor(self, A, b: np.ndarray, key: str, x0=None,
                              direct: Callable | None = None,
                              accept: float | None = None) -> np.ndarray:
        """PCG with the kept factor; the renewal rule drops the factor once one PCG solve costs
        more than the average cost per solve since it was made (factorisation included), so the
        next solve refactorises; a PCG solve that misses the tolerance within the cap
        refactorises now (by ``direct(A, b, keep)``, default SuperLU with ordering reuse)."""
        import scipy.sparse as sp

        kept = self._kept.get(key)
        b = np.asarray(b, dtype=float)
        if kept is not None and tuple(kept.factor.shape) == A.shape and b.any():
            t0 = time.perf_counter()
            spec = replace(self.spec, method="pcg", preconditioner=kept.factor,
                           maxiter=REUSE_MAX_ITERATIONS, options={"check_symmetry": False})
            res = self.run(sp.csr_matrix(A), b, x0, spec=spec)
            spent = time.perf_counter() - t0
            self._time("time_pcg", spent)
            self._count("linear_solves")
            self._count("linear_iterations", int(res.iterations))
            if res.converged:
                kept.solves += 1
                kept.solve_time += spent
                if spent * kept.solves > kept.factor_time + kept.solve_time:
                    self._kept.pop(key, None)  # marginal cost above the average: refactorise next
                return np.asarray(res.x, dtype=float)
            self._count("refactorizations")
        if direct is not None:  # e.g. the Cholesky refactorisation on a fixed pattern
            return direct(A, b, key)
        return self._solve_direct(A, b, keep=key, accept=accept)

    def _checked_solve(self, factor: Factor, A, b: np.ndarray, bnorm: float, name: str,
                       accept: float | None = None) -> np.ndarray:
        """``factor.solve(b)`` (timed as ``time_solve``) under the direct solvers' residual rule
        ``||b - A x|| <= max(rtol ||b||, atol)``; :class:`~femkit.errors.SolverError` otherwise.

        An answer that misses the rule is refined (iterative refinement with the same factor,
        ``x += factor.solve(b - A x)``, at most :data:`REFINEMENT_STEPS` times while the
        residual falls: Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed.,
        ch. 12; ``stats["refinements"]``), as a stiff barrier's ill-conditioned Newton matrix
        needs; what still misses it is accepted only up to the caller's ``accept``
        (``stats["inexact_solves"]``)."""
        t0 = time.perf_counter()
        x = factor.solve(b)
        r = b - A @ x
        res = norm2(r)
        rtol, atol = self.spec.rtol, self.spec.atol
        goal = max(rtol * bnorm, atol)
        for _ in range(REFINEMENT_STEPS):
            if not np.isfinite(res) or res <= goal:
                break
            x_new = x + factor.solve(r)
            r_new = b - A @ x_new
            res_new = norm2(r_new)
            if not res_new < res:
                break
            x, r, res = x_new, r_new, res_new
            self._count("refinements")
        self._time("time_solve", time.perf_counter() - t0)
        if np.isfinite(res) and res > goal and accept is not None and res <= accept * bnorm:
            self._count("inexact_solves")
        elif not (np.isfinite(res) and res <= goal):
            raise SolverError(
                f"linear solve ({name}) missed the residual rule: relative residual {res / bnorm:.3e} "
                f"> rtol {rtol:.1e}; the matrix is numerically singular or very ill-conditioned")
        return x

    # ------------------------------------------------------------------ fixed pattern
    def solve_on_pattern(self, A, b: np.ndarray, pattern, keep: str | None = None,
                         key: str = "pattern", accept: float | None = None) -> np.ndarray:
        """Solve ``A x = b`` for an SPD ``A`` assembled into a fixed ``pattern`` (the same object
        every call) with the ``cholesky`` engine of the spec; with ``keep``, PCG preconditioned
        by the kept (older) factor first, under the renewal rule of :meth:`solve`.

        ``pattern`` groups the entries of ``A``'s CSR pattern: ``entry_group`` (one int per
        entry, ``< n_groups``) and ``kept_groups`` (groups always factorised). Groups whose
        entries have all been exactly zero so far (the out-of-plane couplings of a planar cloth)
        are left out of the factor, which exploits them; all entries of a group enter once one
        of them is nonzero. So the analysed pattern changes only when such a group wakes up,
        and every other call refactorises in place on the kept symbolic analysis
        (``stats["symbolic_reuses"]``).
        """
        if keep is None:
            return self._solve_on_pattern(A, b, pattern, key, accept=accept)
        return self._solve_reusing_factor(
            A, b, keep, direct=lambda A, b, kept: self._solve_on_pattern(A, b, pattern, key, kept,
                                                                        accept))

    def _solve_on_pattern(self, A, b: np.ndarray, pattern, key: str,
                          keep: str | None = None, accept: float | None = None) -> np.ndarray:
        import scipy.sparse as sp

        from .cholesky import factorize_spd

        self._count("linear_solves")
        b = np.asarray(b, dtype=float)
        if not b.any():   # b = 0 decided by its entries, not by a norm that may underflow
            return np.zeros_like(b)
        bnorm = norm2(b)
        kept = self._pattern.get(key)
        t0 = time.perf_counter()
        group = pattern.entry_group
        seen = np.bincount(group[A.data != 0.0], minlength=pattern.n_groups) > 0
        seen[pattern.kept_groups] = True
        if kept is not None and kept[0] is pattern:
            seen |= kept[1]
        if kept is not None and kept[0] is pattern and np.array_equal(seen, kept[1]):
            mask = kept[2]
            Ac = sp.csr_matrix((A.data[mask], kept[4], kept[3]), shape=A.shape)
            factor = kept[5].refactor(Ac)
        else:
            mask = seen[group]
            counts = np.concatenate([[0], np.cumsum(mask)])
            Ac = sp.csr_matrix((A.data[mask], A.indices[mask], counts[A.indptr]), shape=A.shape)
            factor = factorize_spd(Ac, engine=self.engine, check_symmetry=False)
            self._pattern[key] = (pattern, seen, mask, Ac.indptr, Ac.indices, factor)
        self._count("factorizations")
        if factor.info["symbolic_reused"]:
            self._count("symbolic_reuses")
        spent = time.perf_counter() - t0
        self._time("time_factorization", spent)
        if keep is not None:  # preconditions later solves (reuse_factorization)
            self._kept[keep] = _Kept(factor, spent)
        return self._checked_solve(factor, Ac, b, bnorm, "cholesky", accept)
