"""Sparse Cholesky for symmetric positive definite systems (CHOLMOD, supernodal), with the
symbolic analysis computed once per sparsity pattern and reused by every refactorisation.

CHOLMOD (Chen, Davis, Hager, Rajamanickam 2008, "Algorithm 887: CHOLMOD, supernodal sparse
Cholesky factorization and update/downdate", ACM TOMS 35(3)) through scikit-sparse. A
factorisation has two parts:

* the *symbolic analysis*: a fill-reducing ordering (AMD, METIS nested dissection ...), the
  elimination tree, the supernodes and the pattern of ``L``; it depends only on the sparsity
  pattern of ``A``;
* the *numeric factorisation* ``P A P^T = L L^T`` on that structure, dense BLAS-3 kernels on
  the supernodes.

Time-stepping methods refactor a matrix of one fixed pattern every step (Baraff-Witkin,
Newton), so the analysis is cached, keyed on the pattern (shape, ``indptr``, ``indices``;
a BLAKE2 digest of them, confirmed by an exact comparison): :func:`factorize_spd` /
:func:`cholesky` reuse it for every matrix of that pattern (``info["symbolic_reused"]``,
``info["symbolic_uses"]`` count it), and :meth:`CholeskyFactor.refactor` refactors a factor in
place without even hashing the pattern (the caller guarantees it).

Positive definiteness is never assumed silently: an asymmetric matrix, or one on which
CHOLMOD meets a non-positive pivot, raises :class:`~femkit.errors.NotSPDError` (no fallback to
LU: SuperLU stays available as the ``direct`` method, chosen explicitly).

Why scikit-sparse rather than cholespy (measured on the Baraff-Witkin matrices of the benchmark
cloths, one thread): cholespy ships CHOLMOD's *simplicial* factorisation and has no
refactorisation entry point (every matrix pays the ordering again), and was as slow as SuperLU
in symmetric mode (81 x 81 cloth, n = 19,677: 0.26-0.45 s vs 0.20-0.41 s); scikit-sparse's
supernodal factorisation on the reused analysis took 0.09-0.10 s there and 0.40 s vs 1.57 s
(SuperLU) on the 128 x 128 cloth (n = 49,146). It links the system's SuiteSparse (Debian:
``libsuitesparse-dev``) and BLAS (OpenBLAS: ``libopenblas0-pthread``; the reference BLAS is
~2.5x slower on the supernodes).

>>> import numpy as np, scipy.sparse as sp
>>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(4, 4), format="csr")
>>> r = cholesky(A, np.ones(4))
>>> r.converged, np.round(r.x, 12).tolist()
(True, [2.0, 3.0, 3.0, 2.0])
"""

from __future__ import annotations

import hashlib
import time
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError, NotSPDError
from .core.checks import (SYMMETRY_TOL, as_operator, asymmetry, dependency_boundary, finish, prepare,
                     zero_rhs_result)
from .core import defaults
from .factor import NOT_SPD_ADVICE, Factor
from .core.result import SolveResult

__all__ = ["CholeskyFactor", "cholesky", "factorize_spd", "clear_symbolic_cache",
           "symbolic_cache_info", "ORDERINGS", "DEFAULT_ORDERING", "MODES", "ENGINES"]

#: CHOLMOD orderings accepted by ``ordering=``.
ORDERINGS = ("default", "best", "amd", "metis", "nesdis", "natural")

#: Default ordering: CHOLMOD's nested dissection (``nesdis``: METIS partitions, constrained
#: minimum degree on the parts). Measured on the benchmark cloths' Baraff-Witkin matrices on an
#: unloaded machine (one thread, numeric refactorisation on the cached analysis): Liu's 81 x 81
#: cloth 110 ms against 155 ms for AMD (flops 328M against 485M), the 128 x 128 cloth 356 ms
#: against 438 ms (1.30G against 1.79G flops). Its analysis costs 3-5x AMD's (47 ms against
#: 13 ms at n = 19,677) but is paid once per pattern and is still won back on one factorisation.
DEFAULT_ORDERING = "nesdis"

#: CHOLMOD factorisation kinds accepted by ``mode=``: ``supernodal`` (dense BLAS-3 kernels on
#: the supernodes: the fastest numeric factorisation) and ``simplicial`` (column by column: a
#: slower factorisation but a faster triangular solve on small 2-D patterns, 0.58 ms against
#: 0.75 ms for three right-hand sides on the fast mass-spring matrix of Liu's cloth, n = 6,557,
#: so the mode for a matrix factorised once and solved many times).
MODES = ("supernodal", "simplicial")

#: Factorisation libraries accepted by ``engine=``: ``cholmod`` (SuiteSparse CHOLMOD through
#: scikit-sparse, the default; the fastest solves) and ``pardiso`` (Intel oneMKL PARDISO,
#: :mod:`femkit.solvers.pardiso`; the fastest numeric factorisation, 2.5-3.5x CHOLMOD's on the
#: cloth matrices, so the engine for a matrix refactorised every step) and ``cholespy`` (CHOLMOD
#: bundled in the cholespy wheel, :class:`femkit.solvers.factor.CholespyFactor`: pip alone, any
#: OS; no separate numeric phase). Chosen by name only.
ENGINES = ("cholmod", "pardiso", "cholespy")

#: Number of sparsity patterns whose symbolic analysis is kept (least recently used dropped).
CACHE_SIZE = 8

_CACHE: "OrderedDict[tuple, _Symbolic]" = OrderedDict()


class _Symbolic:
    """One cached symbolic analysis: the pattern it belongs to and how often it served."""

    def __init__(self, factor, indptr: np.ndarray, indices: np.ndarray, ordering: str,
                 analysis_time: float, mode: str = "supernodal"):
        self.factor = factor            # an analysed (not factorised) sksparse Factor
        self.indptr = indptr
        self.indices = indices
        self.ordering = ordering
        self.mode = mode
        self.analysis_time = analysis_time
        self.uses = 0
        self.owned = False              # a CholeskyFactor refactorises ``factor`` in place


def available() -> bool:
    """Whether scikit-sparse (CHOLMOD), the optional dependency of ``cholesky``, can be imported."""
    try:
        from sksparse import cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def _cholmod():
    try:
        from sksparse import cholmod
    except ImportError:
        from ..errors import BackendUnavailableError

        raise BackendUnavailableError(
            "the cholesky solver needs scikit-sparse (CHOLMOD), an optional dependency that builds "
            "against the system's SuiteSparse: run `bash scripts/install-cholesky.sh` (Debian: "
            "apt-get install libsuitesparse-dev libopenblas0-pthread, then pip install -e "
            "'.[cholesky]'), or use method 'direct'") from None
    return cholmod


def _check_ordering(ordering: str, mode: str = "supernodal") -> None:
    from ..errors import UnknownNameError

    if ordering not in ORDERINGS:
        raise UnknownNameError("cholesky ordering", ordering, ORDERINGS)
    if mode not in MODES:
        raise UnknownNameError("cholesky mode", mode, MODES)


def _as_symmetric_csc(A, check_symmetry: bool) -> sp.csc_matrix:
    """A validated square float64 matrix as CSC with sorted indices (its CSR arrays reused:
    for a symmetric matrix CSR and CSC hold the same arrays)."""
    if isinstance(A, LinearOperator):
        raise InputError("the cholesky solver needs an explicit matrix, not a LinearOperator")
    A = as_operator(A)
    if isinstance(A, LinearOperator):  # pragma: no cover - handled above
        raise InputError("the cholesky solver needs an explicit matrix")
    if not sp.issparse(A):
        A = sp.csr_matrix(A)
    A = A.tocsr()
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    if check_symmetry:
        a = asymmetry(A)
        if a > SYMMETRY_TOL:
            raise NotSPDError(
                f"cholesky needs a symmetric positive definite matrix, but A is not symmetric: "
                f"||A - A^T||_inf / ||A||_inf = {a:.3e} > {SYMMETRY_TOL:.0e} (use method "
                f"'direct' (SuperLU) for nonsymmetric systems)")
    return sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape)


def _pattern_key(A: sp.csc_matrix, ordering: str, mode: str) -> tuple:
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(A.indptr, dtype=np.int64).view(np.uint8))
    h.update(np.ascontiguousarray(A.indices, dtype=np.int64).view(np.uint8))
    return (A.shape[0], A.nnz, ordering, mode, h.hexdigest())


def _symbolic(A: sp.csc_matrix, ordering: str, mode: str = "supernodal") -> tuple[_Symbolic, bool]:
    """The cached analysis of ``A``'s pattern (computed now if absent) and whether it was reused."""
    key = _pattern_key(A, ordering, mode)
    sym = _CACHE.get(key)
    if sym is not None and np.array_equal(sym.indptr, A.indptr) \
            and np.array_equal(sym.indices, A.indices):
        _CACHE.move_to_end(key)
        return sym, True
    cholmod = _cholmod()
    t0 = time.perf_counter()
    with dependency_boundary("cholesky (CHOLMOD analysis)", A):
        f = cholmod.analyze(A, mode=mode, ordering_method=ordering)
    sym = _Symbolic(f, A.indptr.copy(), A.indices.copy(), ordering, time.perf_counter() - t0, mode)
    _CACHE[key] = sym
    while len(_CACHE) > CACHE_SIZE:
        _CACHE.popitem(last=False)
    return sym, False


def clear_symbolic_cache() -> None:
    """Forget every cached symbolic analysis."""
    _CACHE.clear()


def symbolic_cache_info() -> list[dict]:
    """One dict per cached pattern: ``n``, ``nnz``, ``ordering``, ``uses``, ``analysis_time``."""
    return [{"n": k[0], "nnz": k[1], "ordering": s.ordering, "mode": s.mode, "uses": s.uses,
             "analysis_time": s.analysis_time} for k, s in _CACHE.items()]


def _numeric(run, what: str):
    """Run a CHOLMOD numeric factorisation, mapping a non-positive pivot to NotSPDError."""
    cholmod = _cholmod()
    with dependency_boundary(what):   # any other CHOLMOD failure, its message kept as the cause
        try:
            return run()
        except cholmod.CholmodNotPositiveDefiniteError as e:
            raise NotSPDError(
                f"{what}: the matrix is not positive definite (CHOLMOD met a non-positive pivot: "
                f"{e}); {NOT_SPD_ADVICE}") from e


class CholeskyFactor(Factor):
    """``P A P^T = L L^T`` of a sparse SPD matrix (CHOLMOD supernodal), reusable for many solves.

    The :class:`~femkit.solvers.factor.Factor` interface: ``solve(b)`` (``b`` of shape
    ``(n,)`` or ``(n, k)``), ``refactor(A)``, ``shape``, ``symmetric`` (True), ``setup_time``, ``info``.

    Attributes
    ----------
    info : dict
        ``nnz_A``, ``ordering``, ``symbolic_reused`` (the analysis
        came from the cache), ``symbolic_uses`` (numeric factorisations the analysis has served,
        this one included), ``analysis_time``, ``numeric_time``, ``backend``.
    """

    symmetric = True

    def __init__(self, factor, shape, sym: _Symbolic, reused: bool, numeric_time: float):
        self._f = factor
        self.shape = tuple(shape)
        self._sym = sym
        self.setup_time = numeric_time + (0.0 if reused else sym.analysis_time)
        self.info = {"backend": f"cholmod-{sym.mode} (scikit-sparse)", "ordering": sym.ordering,
                     "mode": sym.mode,
                     "symbolic_reused": bool(reused), "symbolic_uses": sym.uses,
                     "analysis_time": sym.analysis_time, "numeric_time": numeric_time,
                     "symmetric": True}
        self.info["nnz_A"] = int(sym.indices.size)

    def refactor(self, A) -> "CholeskyFactor":
        """Numeric refactorisation, in place, of a matrix with *exactly* this factor's pattern
        (the caller guarantees it: the pattern is not compared). Returns ``self``.

        Raises :class:`~femkit.errors.NotSPDError` on a non-positive pivot."""
        A = A if sp.isspmatrix_csc(A) or isinstance(A, sp.csc_array) else \
            sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape)
        if A.shape != self.shape or A.nnz != self._sym.indices.size:
            raise InputError(f"refactor: A is {A.shape} with {A.nnz} entries, the factor's pattern "
                             f"is {self.shape} with {self._sym.indices.size}")
        t0 = time.perf_counter()
        _numeric(lambda: self._f.cholesky_inplace(A), "cholesky refactor")
        dt = time.perf_counter() - t0
        self._sym.uses += 1
        self.setup_time = dt
        self.info.update(symbolic_reused=True, symbolic_uses=self._sym.uses, numeric_time=dt)
        return self

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return self._f(b)


def factorize_spd(A, *, ordering: str = DEFAULT_ORDERING, mode: str = "supernodal",
                  engine: str | None = None, check_symmetry: bool = True):
    """Cholesky factorisation of a sparse SPD matrix, reusing the cached symbolic analysis of
    its pattern (module docstring).

    Parameters
    ----------
    A : sparse matrix or ndarray, shape (n, n)
        Symmetric positive definite.
    ordering : str
        CHOLMOD fill-reducing ordering, one of :data:`ORDERINGS` (default
        :data:`DEFAULT_ORDERING`). Part of the cache key.
    mode : str
        ``"supernodal"`` (default: the fastest factorisation) or ``"simplicial"`` (the faster
        triangular solves on small 2-D patterns: for a matrix factorised once and solved many
        times), see :data:`MODES`. Part of the cache key. CHOLMOD only.
    engine : str
        ``"cholmod"`` (default) or ``"pardiso"`` (:data:`ENGINES`): the latter returns a
        :class:`femkit.solvers.pardiso.PardisoFactor` (same interface) whose analysis is kept by
        the factor itself (``refactor``), not in the pattern cache.
    check_symmetry : bool
        Check ``||A - A^T||_inf <= 1e-10 ||A||_inf`` (one transpose); CHOLMOD itself reads only
        one triangle.

    Raises
    ------
    NotSPDError
        ``A`` is not symmetric, or not positive definite.
    """
    engine = defaults.DEFAULT_ENGINE if engine is None else engine
    if engine not in ENGINES:
        from ..errors import UnknownNameError

        raise UnknownNameError("cholesky engine", engine, ENGINES)
    if engine == "cholespy":
        from .factor import CholespyFactor

        return CholespyFactor(_as_symmetric_csc(A, check_symmetry))
    if engine == "pardiso":
        if mode != "supernodal":
            raise InputError(f"cholesky: mode {mode!r} is CHOLMOD's (engine 'cholmod'); PARDISO "
                             "factorises supernodally")
        from .pardiso import factorize_pardiso

        Ac = _as_symmetric_csc(A, check_symmetry)
        if Ac.shape[0] == 0:
            raise InputError("A is empty (0 x 0)")
        # symmetric: the CSC arrays are the CSR arrays of the same matrix
        return factorize_pardiso(sp.csr_matrix((Ac.data, Ac.indices, Ac.indptr), shape=Ac.shape),
                                 ordering)
    _check_ordering(ordering, mode)
    Ac = _as_symmetric_csc(A, check_symmetry)
    if Ac.shape[0] == 0:
        raise InputError("A is empty (0 x 0)")
    sym, reused = _symbolic(Ac, ordering, mode)
    t0 = time.perf_counter()
    if not sym.owned:  # the first factor of an analysis takes it over (no copy) ...
        sym.owned = True
        f = _numeric(lambda: sym.factor.cholesky_inplace(Ac) or sym.factor, "cholesky")
    else:              # ... later ones copy it (its owner may refactorise it in place: the
        f = _numeric(lambda: sym.factor.cholesky(Ac), "cholesky")  # analysis stays valid)
    dt = time.perf_counter() - t0
    sym.uses += 1
    return CholeskyFactor(f, Ac.shape, sym, reused, dt)


def cholesky(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None,
             maxiter=None, M=None, callback=None, factorization: CholeskyFactor | None = None,
             ordering: str = DEFAULT_ORDERING, engine: str | None = None,
             check_symmetry: bool = True) -> SolveResult:
    """Solve ``A x = b`` for SPD ``A`` by sparse Cholesky (see :func:`factorize_spd`).

    Same contract as :func:`femkit.solvers.direct.direct`: ``x0``, ``maxiter``, ``M`` and
    ``callback`` are accepted for signature uniformity and ignored; ``converged`` is decided on
    the true residual ``||b - A x|| <= max(rtol ||b||, atol)``; ``reason`` is ``"direct"``.
    ``info`` holds the factor (``info["factorization"]``, for reuse) and the symbolic-analysis
    counters ``symbolic_reused`` / ``symbolic_uses``. ``engine``: ``"cholmod"`` (default) or
    ``"pardiso"`` (:data:`ENGINES`; in a case or scene file ``options: {engine: pardiso}``).

    Raises
    ------
    NotSPDError
        ``A`` is not symmetric, or CHOLMOD meets a non-positive pivot (never a silent switch
        to LU).
    """
    prob = prepare(A, b, None, rtol=rtol, atol=atol, maxiter=maxiter, method="cholesky")
    if isinstance(prob.A, LinearOperator):
        raise InputError("the cholesky solver needs an explicit matrix, not a LinearOperator")
    if factorization is None:
        factorization = factorize_spd(prob.A, ordering=ordering, engine=engine,
                                      check_symmetry=check_symmetry)
        setup = factorization.setup_time
    else:
        if tuple(factorization.shape) != prob.A.shape:
            raise InputError(f"factorization is {factorization.shape}, A is {prob.A.shape}")
        setup = 0.0
    if prob.b_is_zero:
        res = zero_rhs_result(prob, method="cholesky")
        res.reason = "direct"
        res.info = {**factorization.info, "factorization": factorization}
        return res
    t0 = time.perf_counter()
    prob.x = factorization.solve(prob.b)
    dt = time.perf_counter() - t0
    res = finish(prob, iterations=0, residuals=[prob.rhs_norm], method="cholesky",
                 reason="converged", info={**factorization.info, "factorization": factorization})
    if res.converged:
        res.message = f"cholesky solve, true residual {res.true_residual:.3e}"
    else:
        res.message = (f"cholesky solve: true residual {res.true_residual:.3e} exceeds tolerance "
                       f"{res.tolerance:.3e}; the matrix is very ill-conditioned")
    res.reason = "direct" if np.all(np.isfinite(prob.x)) else "non-finite"
    res.setup_time, res.solve_time = setup, dt
    return res


#: Option values checked when a case, scene or study is loaded (:func:`femkit.solvers.core.checks.check_options`).
cholesky.option_choices = {"engine": ("cholesky engine", ENGINES),
                           "ordering": ("cholesky ordering", ORDERINGS)}
