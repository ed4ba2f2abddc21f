"""Spring geometry, Hooke/dashpot kernels, the spring Jacobian blocks and their sparse assembly.

Conventions (Schlögl, mass-spring forces; Baraff & Witkin 1998, section 5)
---------------------------------------------------------------------------
A spring ``s = (i, j)`` with stiffness ``k``, rest length ``L`` and current vector
``x_ij = x_j - x_i``, length ``l = |x_ij|``, direction ``u = x_ij / l`` exerts

    f_i = k (l - L) u,        f_j = -f_i

(stretched springs pull ``i`` toward ``j``), with energy ``1/2 k (l - L)^2``. The
``d x d`` block of ``K = -df/dx`` (the Hessian of that energy) is

    H_s = k [ (1 - L/l) (I - u u^T) + u u^T ]  =  k ( I - (L/l) (I - u u^T) )

and enters ``K`` with ``+H_s`` on the ``(i, i)`` and ``(j, j)`` blocks and ``-H_s`` on
``(i, j)`` and ``(j, i)``. Its eigenvalues are ``k`` (along ``u``) and ``k (1 - L/l)``
(``d - 1`` times, across ``u``): a compressed spring (``l < L``) makes ``K`` indefinite.

Definiteness fixes (Hessian modification: Nocedal & Wright, Numerical Optimization, section 3.4)
-----------------------------------------------------------------------------------------------
``fix="clamp"``
    per-spring eigenvalue clamp: ``(1 - L/l)`` is replaced by ``max(0, 1 - L/l)``, which
    is exactly ``Q max(0, Lambda) Q^T`` of the block because ``u`` and its complement are
    the eigenvectors. Every block is then PSD, hence so is ``K`` (sum of ``A_s A_s^T (x) H_s``).
``fix="regularize"``
    global shift ``K + mu I`` with the analytic bound :func:`regularization_shift`
    (instead of a trial-factorisation loop ``reg = 1, 10, 100 ...``, which
    needs a factorisation per trial).

Zero-length springs: the length is floored at ``length_floor`` (``1e-12`` times the
largest rest length), where ``u`` is set to zero; forces and blocks stay finite.

The scatter from spring-major data to the global matrix uses a :class:`SpringPattern`
built once per topology: ``np.bincount`` over a precomputed inverse map, so every step
only computes the ``4 s d^2`` block values.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = [
    "SpringPattern",
    "spring_blocks",
    "dashpot_blocks",
    "spring_block_product",
    "regularization_shift",
    "nodal_block_matrix",
    "FIXES",
]

FIXES = (None, "clamp", "regularize")


def _transverse_factor(length, rest, fix):
    a = 1.0 - rest / length
    if fix == "clamp":
        a = np.maximum(a, 0.0)
    return a


def spring_blocks(length: np.ndarray, u: np.ndarray, k, rest, fix: str | None = None) -> np.ndarray:
    """The ``(s, d, d)`` blocks ``H_s = k [(1 - L/l)(I - u u^T) + u u^T]``.

    ``fix="clamp"`` clamps the transverse eigenvalue ``k (1 - L/l)`` at zero.

    >>> H = spring_blocks(np.array([0.5]), np.array([[1., 0.]]), 2.0, 1.0)
    >>> H[0].tolist()      # along u: k = 2; across: k (1 - L/l) = -2
    [[2.0, 0.0], [0.0, -2.0]]
    >>> spring_blocks(np.array([0.5]), np.array([[1., 0.]]), 2.0, 1.0, fix="clamp")[0].tolist()
    [[2.0, 0.0], [0.0, 0.0]]
    """
    s, d = u.shape
    a = np.broadcast_to(k * _transverse_factor(length, rest, fix), (s,))
    kk = np.broadcast_to(np.asarray(k, dtype=float), (s,))
    uu = u[:, :, None] * u[:, None, :]
    H = (kk - a)[:, None, None] * uu
    idx = np.arange(d)
    H[:, idx, idx] += a[:, None]
    return H


def dashpot_blocks(u: np.ndarray, c) -> np.ndarray:
    """The ``(s, d, d)`` blocks ``c u u^T`` of ``D = -df/dv`` of the dashpots."""
    s = u.shape[0]
    cc = np.broadcast_to(np.asarray(c, dtype=float), (s,))
    return cc[:, None, None] * (u[:, :, None] * u[:, None, :])


def spring_block_product(length, u, k, rest, ddiff, fix: str | None = None) -> np.ndarray:
    """``H_s (d_j - d_i)`` for every spring without forming ``H_s``.

    ``H dd = k [ a dd + (1 - a) u (u . dd) ]`` with ``a = 1 - L/l`` (clamped for ``fix="clamp"``).
    """
    a = _transverse_factor(length, rest, fix)
    ud = np.einsum("sd,sd->s", u, ddiff)
    return (k * a)[:, None] * ddiff + (k * (1.0 - a) * ud)[:, None] * u


def regularization_shift(n: int, i, j, length, rest, k, extra=None) -> float:
    """A shift ``mu >= 0`` with ``K + mu I`` positive semi-definite (proof below).

    Split ``H_s = H_s^+ + N_s`` with ``N_s = k min(0, 1 - L/l)(I - u u^T)``, whose smallest
    eigenvalue is ``-c_s``, ``c_s = k max(0, L/l - 1)``. The clamped part is PSD, and for any
    ``z``: ``(z_i - z_j)^T N_s (z_i - z_j) >= -c_s |z_i - z_j|^2 >= -2 c_s (|z_i|^2 + |z_j|^2)``.
    Summing over springs, ``z^T K z >= -max_node (2 sum_{s at node} c_s + e_node) |z|^2``
    where ``e_node`` (``extra``) bounds the negative part of nodal (contact) blocks.
    That maximum is ``mu``. It is zero when no spring is compressed.
    """
    c = k * np.maximum(rest / length - 1.0, 0.0)
    c = np.broadcast_to(c, (len(i),))
    per_node = 2.0 * (np.bincount(i, weights=c, minlength=n) + np.bincount(j, weights=c, minlength=n))
    if extra is not None:
        per_node = per_node + extra
    return float(per_node.max()) if n else 0.0


class SpringPattern:
    """Sparsity pattern and scatter map of the spring matrices, computed once per topology.

    The pattern holds the four ``d x d`` blocks of every spring plus the full diagonal
    (so that ``M + h^2 K`` and ``K + mu I`` keep the same structure).

    Parameters
    ----------
    n, dim : number of nodes and space dimension.
    i, j : (s,) spring ends.

    >>> p = SpringPattern(2, 1, np.array([0]), np.array([1]))
    >>> p.assemble(np.array([[[3.0]]])).toarray().tolist()
    [[3.0, -3.0], [-3.0, 3.0]]
    """

    def __init__(self, n: int, dim: int, i: np.ndarray, j: np.ndarray):
        d = dim
        self.n, self.dim, self.ndof = n, d, n * d
        a = np.arange(d)
        # block entry (p, q): row node*d + p, col node*d + q, laid out like H.reshape(s, d*d)
        rp = np.repeat(a, d)           # p for each of the d*d entries
        cq = np.tile(a, d)             # q
        ri = (i[:, None] * d + rp).ravel()
        rj = (j[:, None] * d + rp).ravel()
        ci = (i[:, None] * d + cq).ravel()
        cj = (j[:, None] * d + cq).ravel()
        diag = np.arange(self.ndof)
        rows = np.concatenate([ri, rj, ri, rj, diag])
        cols = np.concatenate([ci, cj, cj, ci, diag])
        keys = rows.astype(np.int64) * self.ndof + cols
        uniq, inv = np.unique(keys, return_inverse=True)
        self._inv = inv.astype(np.intp)
        self._nblock = 4 * len(ri)
        self.nnz = len(uniq)
        urows = uniq // self.ndof
        self.indices = (uniq % self.ndof).astype(np.int32)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(urows, minlength=self.ndof))]).astype(np.int32)
        self._diag_pos = self._inv[self._nblock:]
        self._zero_tail = np.zeros(self.ndof)

    def assemble(self, blocks: np.ndarray, diagonal: np.ndarray | float | None = None) -> sp.csr_matrix:
        """CSR matrix from per-spring blocks ``(s, d, d)`` (+ an optional added diagonal)."""
        b = blocks.reshape(len(blocks), self.dim * self.dim)
        tail = self._zero_tail if diagonal is None else np.broadcast_to(diagonal, (self.ndof,))
        w = np.concatenate([b.ravel(), b.ravel(), -b.ravel(), -b.ravel(), tail])
        data = np.bincount(self._inv, weights=w, minlength=self.nnz)
        return sp.csr_matrix((data, self.indices.copy(), self.indptr.copy()), shape=(self.ndof, self.ndof))


def nodal_block_matrix(ndof: int, dim: int, nodes: np.ndarray, blocks: np.ndarray) -> sp.csr_matrix:
    """CSR matrix with ``d x d`` blocks on the diagonal block of each listed node."""
    d = dim
    a = np.arange(d)
    rows = (nodes[:, None, None] * d + a[None, :, None] + 0 * a[None, None, :]).ravel()
    cols = (nodes[:, None, None] * d + a[None, None, :] + 0 * a[None, :, None]).ravel()
    return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(ndof, ndof))
