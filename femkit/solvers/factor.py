"""The one interface of a kept sparse factorisation, and the factor of a permuted matrix.

Every engine femkit factorises with (SuperLU in :mod:`femkit.solvers.direct`, CHOLMOD in
:mod:`femkit.solvers.cholesky`, MKL PARDISO in :mod:`femkit.solvers.pardiso`) returns a
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

__all__ = ["Factor", "PermutedFactor", "NOT_SPD_ADVICE"]

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
