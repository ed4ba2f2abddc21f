"""Sparse Cholesky by Intel oneMKL PARDISO (``engine="pardiso"`` of the ``cholesky`` solver).

PARDISO (Schenk and Gärtner, "Solving unsymmetric sparse systems of linear equations with
PARDISO", Future Generation Computer Systems 20(3), 2004; Intel oneMKL Developer Reference,
"oneMKL PARDISO - Parallel Direct Sparse Solver Interface") factors a symmetric positive
definite matrix (``mtype = 2``) in three phases: 11 = analysis (METIS nested dissection,
symbolic factorisation), 22 = numeric factorisation, 33 = solve. A :class:`PardisoFactor` keeps
its analysis: :meth:`PardisoFactor.refactor` runs phase 22 only, for a matrix of the same
pattern (what the implicit integrators do every step).

Why a second engine next to CHOLMOD (:mod:`femkit.solvers.cholesky`): measured on the
Baraff-Witkin matrices of the benchmark cloths, one thread, numeric factorisation on a kept
analysis, PARDISO takes 114 ms against CHOLMOD's 292 ms on the 128 x 128 cloth (n = 49,146, about
the same fill: nnz(L) 6.0M against 5.6M) and 35 ms against 122 ms on Liu's 81 x 81 cloth, while
its solve with three right-hand sides is slower (2.6 ms against CHOLMOD's simplicial 0.6 ms on
the fast mass-spring matrix). So a matrix refactorised every step goes to PARDISO, a matrix
factorised once and solved many times to CHOLMOD; both are chosen by name, never by fallback.

MKL comes as a binary wheel (``pip install mkl``, the optional extra ``femkit[pardiso]``); its
``mkl_rt`` library is called through ``ctypes`` with 32-bit indices (LP64), zero-based
(``iparm[34] = 1``), so the CSR arrays are passed without copies. Threads follow MKL's own
setting (``MKL_NUM_THREADS``).
"""

from __future__ import annotations

import ctypes
import glob
import os
import sys
import time

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, NotSPDError
from .factor import NOT_SPD_ADVICE, Factor

__all__ = ["PardisoFactor", "available", "factorize_pardiso"]

#: PARDISO's fill-reducing orderings (``iparm[1]``) by femkit's ordering names.
ORDERINGS = {"metis": 2, "nesdis": 2, "default": 2, "amd": 0}

_LIB = None
_INT_P = ctypes.POINTER(ctypes.c_int32)
_DBL_P = ctypes.POINTER(ctypes.c_double)


def _candidates() -> list[str]:
    """Where MKL's single dynamic library ``mkl_rt`` may be: ``$FEMKIT_MKL_RT``, the ``mkl``
    wheel's ``sys.prefix/lib`` (shortest name first), the system's library path."""
    from ctypes.util import find_library

    paths = [os.environ.get("FEMKIT_MKL_RT")]
    paths += sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len)
    paths.append(find_library("mkl_rt"))
    return [p for p in paths if p]


def _library():
    """The ``pardiso`` entry point of ``mkl_rt``, loaded on first use; ``None`` when MKL is not
    installed."""
    global _LIB
    if _LIB is not None:
        return _LIB
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        fn = lib.pardiso
        fn.restype = None
        fn.argtypes = [ctypes.c_void_p, _INT_P, _INT_P, _INT_P, _INT_P, _INT_P, _DBL_P, _INT_P,
                       _INT_P, _INT_P, _INT_P, _INT_P, _INT_P, _DBL_P, _DBL_P, _INT_P]
        _LIB = fn
        return fn
    return None


def available() -> bool:
    """Whether MKL PARDISO (the optional ``mkl`` wheel) is installed: its library file is found
    (not loaded: MKL and its OpenMP runtime enter a process only when a factorisation asks)."""
    return _LIB is not None or any(os.path.exists(p) or not os.path.isabs(p) for p in _candidates())


def _require():
    fn = _library()
    if fn is None:
        from ..errors import BackendUnavailableError

        raise BackendUnavailableError(
            "the cholesky engine 'pardiso' needs Intel oneMKL (an optional dependency, binary "
            "wheels): run `pip install -e '.[pardiso]'` (or `pip install mkl`), or use engine "
            "'cholmod'")
    return fn


#: PARDISO error codes (oneMKL Developer Reference, "pardiso", return values).
_ERRORS = {-1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
           -4: "zero or negative pivot", -5: "unclassified (internal) error",
           -6: "reordering failed", -7: "diagonal matrix is singular",
           -8: "32-bit integer overflow", -9: "not enough memory for the out-of-core solver",
           -10: "error opening out-of-core files", -11: "read/write error with OOC files"}


class PardisoFactor(Factor):
    """``A = L L^T`` of a sparse SPD matrix by MKL PARDISO, reusable for many solves.

    The :class:`~femkit.solvers.factor.Factor` interface: ``solve(b)`` (``b``
    of shape ``(n,)`` or ``(n, k)``), ``refactor(A)`` (numeric phase on the kept analysis),
    ``shape``, ``symmetric`` (True), ``setup_time`` and ``info`` (``backend``, ``ordering``,
    ``symbolic_reused``, ``symbolic_uses``, ``analysis_time``, ``numeric_time``, ``nnz_L``).
    """

    symmetric = True

    def __init__(self, A: sp.csr_matrix, ordering: str = "nesdis"):
        if ordering not in ORDERINGS:
            from ..errors import UnknownNameError

            raise UnknownNameError("pardiso ordering", ordering, list(ORDERINGS))
        self._fn = _require()
        n = A.shape[0]
        self.shape = (n, n)
        U = sp.triu(A, format="csr")
        U.sort_indices()
        # the upper-triangle entries of A's pattern, kept so that refactor() extracts values only
        self._upper = np.flatnonzero(A.indices >= np.repeat(np.arange(n), np.diff(A.indptr)))
        self._nnz = A.nnz
        self._ia = np.ascontiguousarray(U.indptr, dtype=np.int32)
        self._ja = np.ascontiguousarray(U.indices, dtype=np.int32)
        self._a = np.ascontiguousarray(U.data, dtype=np.float64)
        self._pt = np.zeros(64, dtype=np.int64)  # PARDISO's internal handle: kept, never moved
        self._iparm = np.zeros(64, dtype=np.int32)
        ip = self._iparm
        ip[0] = 1                 # these values, not the defaults
        ip[1] = ORDERINGS[ordering]
        ip[7] = 0                 # no iterative refinement (SPD: no pivot perturbation)
        ip[9] = 8                 # pivot perturbation 1e-8 (unused for SPD)
        ip[17] = -1               # report nnz(L)
        ip[34] = 1                # zero-based indices
        self._perm = np.zeros(1, dtype=np.int32)
        self.ordering = ordering
        self._n_uses = 0
        t0 = time.perf_counter()
        self._call(11, self._a, np.zeros(1), np.zeros(1), 1)
        self._analysis = time.perf_counter() - t0
        self.info = {"backend": "mkl-pardiso", "ordering": ordering, "mode": "supernodal",
                     "symbolic_reused": False, "symbolic_uses": 0, "analysis_time": self._analysis,
                     "numeric_time": 0.0, "symmetric": True, "nnz_A": int(A.nnz)}
        self.setup_time = self._analysis
        self._numeric(self._a)
        self.setup_time += self.info["numeric_time"]
        self.info["nnz_L"] = int(self._iparm[17])

    def _call(self, phase: int, a: np.ndarray, b: np.ndarray, x: np.ndarray, nrhs: int) -> None:
        one = ctypes.c_int32(1)
        err = ctypes.c_int32(0)
        self._fn(self._pt.ctypes.data, ctypes.byref(one), ctypes.byref(one),
                 ctypes.byref(ctypes.c_int32(2)), ctypes.byref(ctypes.c_int32(phase)),
                 ctypes.byref(ctypes.c_int32(self.shape[0])), a.ctypes.data_as(_DBL_P),
                 self._ia.ctypes.data_as(_INT_P), self._ja.ctypes.data_as(_INT_P),
                 self._perm.ctypes.data_as(_INT_P), ctypes.byref(ctypes.c_int32(nrhs)),
                 self._iparm.ctypes.data_as(_INT_P), ctypes.byref(ctypes.c_int32(0)),
                 b.ctypes.data_as(_DBL_P), x.ctypes.data_as(_DBL_P), ctypes.byref(err))
        if err.value == -4:
            raise NotSPDError(
                f"cholesky (pardiso): the matrix is not positive definite (zero or negative pivot "
                f"at equation {int(self._iparm[29])}); {NOT_SPD_ADVICE}")
        if err.value != 0:
            raise InputError(f"cholesky (pardiso), phase {phase}: error {err.value} "
                             f"({_ERRORS.get(err.value, 'unknown')})")

    def _numeric(self, a: np.ndarray) -> None:
        t0 = time.perf_counter()
        self._a = a
        self._call(22, a, np.zeros(1), np.zeros(1), 1)
        dt = time.perf_counter() - t0
        self._n_uses += 1
        self.setup_time = dt
        self.info.update(symbolic_uses=self._n_uses, numeric_time=dt,
                         symbolic_reused=self._n_uses > 1)

    def refactor(self, A) -> "PardisoFactor":
        """Numeric refactorisation, in place, of a matrix with *exactly* this factor's pattern
        (the caller guarantees it: only the sizes are compared). Returns ``self``.

        Raises :class:`~femkit.errors.NotSPDError` on a zero or negative pivot."""
        if A.shape != self.shape or A.nnz != self._nnz:
            raise InputError(f"refactor: A is {A.shape} with {A.nnz} entries, the factor's pattern "
                             f"is {self.shape} with {self._nnz}")
        self._numeric(np.ascontiguousarray(A.data[self._upper], dtype=np.float64))
        return self

    def _solve(self, b: np.ndarray) -> np.ndarray:
        k = 1 if b.ndim == 1 else b.shape[1]
        bf = np.asfortranarray(b)  # PARDISO stores the right-hand sides column after column
        x = np.empty_like(bf, order="F")
        self._call(33, self._a, bf, x, k)
        return np.ascontiguousarray(x)

    def __del__(self):  # release PARDISO's internal memory (phase -1)
        try:
            if self._fn is not None and np.any(self._pt):
                self._call(-1, self._a, np.zeros(1), np.zeros(1), 1)
        except Exception:  # pragma: no cover - interpreter shutdown
            pass


def factorize_pardiso(A: sp.csr_matrix, ordering: str = "nesdis") -> PardisoFactor:
    """Analyse and factorise a validated symmetric CSR matrix (see :class:`PardisoFactor`)."""
    return PardisoFactor(A, ordering)
