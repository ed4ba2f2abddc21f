"""The one interface of a kept sparse factorisation, and the factor of a permuted matrix.

Every engine femkit factorises with (SuperLU in :mod:`femkit.solvers.direct`, CHOLMOD in
:mod:`femkit.solvers.cholesky`, MKL PARDISO in :mod:`femkit.solvers.pardiso`, CHOLMOD bundled
in the cholespy wheel: :class:`CholespyFactor`) returns a
:class:`Factor`: ``solve(b)`` for one right-hand side ``(n,)`` or a block ``(n, k)``,
``refactor(A)`` for new values on the same sparsity pattern (the numeric phase only, where the
engine offers it), and the counters and facts in ``info``. The checks every solve makes on its
input are written here once; an engine implements only ``_solve``.

>>> import numpy as np, scipy.sparse as sp
>>> from femkit.solvers.direct import factorize
>>> F = factorize(sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(4, 4)))
>>> isinstance(F, Factor), F.symbolic_uses
(True, 1)
>>> F.solve(np.ones(3))
Traceback (most recent call last):
...
femkit.errors.InputError: b has 3 rows, the factor is 4 x 4
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["Factor", "PermutedFactor", "CholespyFactor", "cholespy_available", "NOT_SPD_ADVICE"]

#: The advice every NotSPDError of both Cholesky engines ends with.
NOT_SPD_ADVICE = ("use method 'direct' (SuperLU) for indefinite systems, or a definiteness fix "
                  "(fix='clamp') for spring Jacobians")


class Factor:
    """A factorisation of a sparse ``n x n`` matrix, reusable for many solves.

    Attributes
    ----------
    shape : tuple
        ``(n, n)``.
    symmetric : bool
        Whether the factorisation is symmetric (Cholesky, or SuperLU's symmetric mode).
    setup_time : float
        Seconds the last (re)factorisation took.
    info : dict
        Engine facts (``nnz_L``, ``ordering``, ``symbolic_reused``, ``symbolic_uses`` ...).
    """

    shape: tuple = (0, 0)
    symmetric: bool = False
    setup_time: float = 0.0
    info: dict

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return ``A^-1 b`` for ``b`` of shape ``(n,)`` or ``(n, k)`` (a block of right-hand sides).

        Raises :class:`~femkit.errors.InputError` when ``b`` does not have ``n`` rows.
        """
        b = np.asarray(b, dtype=np.float64)
        if b.ndim not in (1, 2) or b.shape[0] != self.shape[0]:
            rows = b.shape[0] if b.ndim else 0
            raise InputError(f"b has {rows} rows, the factor is {self.shape[0]} x {self.shape[1]}")
        return self._solve(b)

    def _solve(self, b: np.ndarray) -> np.ndarray:  # pragma: no cover - every engine overrides
        raise NotImplementedError

    def refactor(self, A) -> "Factor":
        """Numeric refactorisation of a matrix with exactly this factor's pattern; returns the
        factor. Engines without a separate numeric phase raise
        :class:`~femkit.errors.InputError` (factorise afresh instead)."""
        raise InputError(f"{type(self).__name__} cannot refactor on its analysis; factorise afresh")

    @property
    def symbolic_uses(self) -> int:
        """Numeric factorisations the symbolic analysis behind this factor has served."""
        return int(self.info.get("symbolic_uses", 1))

    def __call__(self, b: np.ndarray) -> np.ndarray:
        return self.solve(b)

    def matvec(self, b: np.ndarray) -> np.ndarray:
        """:meth:`solve` (the factor used as a preconditioner ``M ~ A^-1``)."""
        return self.solve(b)


class PermutedFactor(Factor):
    """The factor of ``A[p][:, p]`` used as a solver for ``A``: ``solve(b) = A^-1 b``.

    Lets a matrix of an already-ordered pattern be factorised in its ordering without paying
    the ordering again (SuperLU with ``permc_spec="NATURAL"``).
    """

    def __init__(self, factor: Factor, perm: np.ndarray):
        self.factor = factor
        self.perm = perm
        self.shape = factor.shape
        self.info = factor.info
        self.setup_time = factor.setup_time

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return self.factor.symmetric

    def _solve(self, b: np.ndarray) -> np.ndarray:
        y = self.factor.solve(b[self.perm])
        x = np.empty_like(y)
        x[self.perm] = y
        return x


def cholespy_available() -> bool:
    """Whether cholespy (a wheel that bundles CHOLMOD: ``pip install "femkit[fast]"``) imports."""
    try:
        import cholespy  # noqa: F401
    except ImportError:
        return False
    return True


class CholespyFactor(Factor):
    """Sparse Cholesky ``A = L L^T`` by CHOLMOD as bundled in the cholespy wheel (Nicolet et al.
    2021, "Large Steps in Inverse Rendering of Geometry"; Chen, Davis, Hager & Rajamanickam 2008
    for CHOLMOD): the ``cholesky`` solver's engine ``cholespy``, installable by pip alone on any
    OS (``pip install "femkit[fast]"``), where scikit-sparse needs the system's SuiteSparse.

    cholespy offers no separate numeric phase: :meth:`refactor` factorises afresh (in place, so
    the factor object stays the one a solver session keeps) and ``symbolic_reused`` is False.

    Raises
    ------
    NotSPDError
        ``A`` is not positive definite (CHOLMOD's pivot check).
    BackendUnavailableError
        cholespy is not installed.
    """

    symmetric = True

    def __init__(self, A):
        self.info = {"backend": "cholmod (cholespy)", "ordering": "cholmod default",
                     "symbolic_reused": False, "symbolic_uses": 1, "symmetric": True}
        self.refactor(A)

    def refactor(self, A) -> "CholespyFactor":
        """Factorise ``A`` (CSR or CSC, symmetric; its lower triangle is read) afresh; returns self."""
        import time

        import scipy.sparse as sp

        from ..errors import BackendUnavailableError, NotSPDError

        try:
            import cholespy
        except ImportError:
            raise BackendUnavailableError(
                "engine 'cholespy' needs the cholespy wheel: pip install \"femkit[fast]\" (or "
                "pip install cholespy)") from None
        A = sp.csr_matrix(A)
        n = A.shape[0]
        if A.shape != (n, n) or n == 0:
            raise InputError(f"A must be square and non-empty, got {A.shape}")
        t0 = time.perf_counter()
        try:
            self._s = cholespy.CholeskySolverD(n, A.indptr.astype(np.int32), A.indices.astype(np.int32),
                                               np.ascontiguousarray(A.data, dtype=np.float64),
                                               cholespy.MatrixType.CSR)
        except ValueError as exc:
            raise NotSPDError(f"cholesky (cholespy): the matrix is not positive definite ({exc}); "
                              f"{NOT_SPD_ADVICE}") from None
        self.shape = (n, n)
        self.setup_time = time.perf_counter() - t0
        self.info.update(nnz_A=int(A.nnz), numeric_time=self.setup_time)
        return self

    def _solve(self, b: np.ndarray) -> np.ndarray:
        b = np.ascontiguousarray(b, dtype=np.float64)
        x = np.zeros_like(b)
        self._s.solve(b, x)
        return x
