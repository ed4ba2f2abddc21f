"""The preconditioner object every factory in :mod:`femkit.solvers.preconditioners` returns."""

from __future__ import annotations

from typing import Callable

import numpy as np


class Preconditioner:
    """An SPD approximation of ``A^-1``, applied as ``z = M(r)`` or ``M.matvec(r)``.

    Attributes
    ----------
    name : str
        Registry name (``"jacobi"``, ``"ic0"``, ``"amg_sa"`` ...).
    shape : tuple
        ``(n, n)``.
    setup_time : float
        Seconds spent building it.
    info : dict
        Facts about the construction (e.g. AMG levels and complexity, IC(0) shift).
    """

    def __init__(self, name: str, apply: Callable[[np.ndarray], np.ndarray], n: int,
                 setup_time: float = 0.0, info: dict | None = None):
        self.name = name
        self._apply = apply
        self.shape = (n, n)
        self.setup_time = setup_time
        self.info = dict(info or {})

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self._apply(r)

    def matvec(self, r: np.ndarray) -> np.ndarray:
        """Same as calling the object: ``z = M r``."""
        return self._apply(r)

    def aslinearoperator(self):
        """A :class:`scipy.sparse.linalg.LinearOperator` view (e.g. for SciPy's ``cg``)."""
        from scipy.sparse.linalg import LinearOperator

        return LinearOperator(self.shape, matvec=self._apply, dtype=np.float64)

    def __repr__(self) -> str:
        return f"Preconditioner({self.name!r}, n={self.shape[0]}, setup_time={self.setup_time:.3g})"
