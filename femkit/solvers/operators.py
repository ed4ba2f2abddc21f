"""Operators a linear solve works on: a sparse matrix restricted to free dofs, and the same
restriction applied matrix-free (products only, never assembled).

>>> import numpy as np
>>> op = free_operator(lambda e: 2.0 * e, np.array([0, 2]), 3)
>>> op.matvec(np.array([1.0, 5.0])).tolist()
[2.0, 10.0]
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["restrict", "free_operator"]


def restrict(A, free: np.ndarray):
    """``A[free][:, free]`` for a sparse matrix (CSR out)."""
    A = A.tocsr()
    return A[free][:, free].tocsr()


def free_operator(product: Callable[[np.ndarray], np.ndarray], free: np.ndarray, ndof: int):
    """The ``LinearOperator`` ``z -> (A e)[free]`` with ``e`` = ``z`` on the ``free`` dofs
    and 0 on the others, i.e. ``A[free][:, free]`` applied without forming it.

    ``product`` maps a flat ``(ndof,)`` vector to ``A e`` (flat or any shape of ``ndof`` entries).
    """
    from scipy.sparse.linalg import LinearOperator

    nf = len(free)

    def matvec(z):
        e = np.zeros(ndof)
        e[free] = np.ravel(z)
        return np.asarray(product(e)).reshape(-1)[free]

    return LinearOperator((nf, nf), matvec=matvec, rmatvec=matvec, dtype=np.float64)
