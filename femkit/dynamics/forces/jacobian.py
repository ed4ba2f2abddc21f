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

    The pattern holds the four ``d x d`` blocks of every spring plus the full diagonal (so that
    ``M + h^2 K`` and ``K + mu I`` keep the same structure), or with ``node_blocks`` every node's
    full ``d x d`` diagonal block (so that nodal force matrices fit too). It is built by femkit's
    one assembly stack, :mod:`femkit.fem.sparsity`: a spring is a 2-node cell of the node-level
    pattern (:func:`~femkit.fem.sparsity.entry_pattern`), each node pair a ``d x d`` block
    (:func:`~femkit.fem.sparsity.block_structure`).

    Parameters
    ----------
    n, dim : number of nodes and space dimension.
    i, j : (s,) spring ends.
    node_blocks : every node's diagonal block, not only the diagonal.

    Attributes
    ----------
    indptr, indices : int32 arrays of the CSR structure (sorted columns).
    slots : (4, s, d*d) int64, the ``data`` position of entry ``p*d + q`` of each spring's blocks
        ``(i, i)``, ``(j, j)``, ``(i, j)``, ``(j, i)``.
    diag : (n*d,) int64, the ``data`` position of each diagonal entry.

    >>> p = SpringPattern(2, 1, np.array([0]), np.array([1]))
    >>> p.assemble(np.array([[[3.0]]])).toarray().tolist()
    [[3.0, -3.0], [-3.0, 3.0]]
    """

    def __init__(self, n: int, dim: int, i: np.ndarray, j: np.ndarray, *, node_blocks: bool = False):
        from ...fem.sparsity import (block_positions, block_structure, cell_entries, entry_pattern,
                                     union_structures)

        d, s, ndof = dim, len(i), n * dim
        self.n, self.dim, self.ndof = n, d, ndof
        rows, cols = cell_entries(np.stack([np.asarray(i), np.asarray(j)], axis=1))
        if node_blocks:
            rows, cols = np.concatenate([rows, np.arange(n)]), np.concatenate([cols, np.arange(n)])
        node_indptr, node_indices, node_slots = entry_pattern(rows, cols, n)
        indptr, indices = block_structure(node_indptr, node_indices, d)
        at = block_positions(node_indptr, node_slots, rows, d)    # (4 s [+ n], d*d)
        if node_blocks:
            self.diag = at[4 * s:, np.arange(d) * (d + 1)].reshape(-1)
        else:  # the diagonal joined in (a node without springs has no block)
            indptr, indices, (moved, self.diag) = union_structures(
                [(indptr, indices), (np.arange(ndof + 1), np.arange(ndof))], ndof)
            at = moved[at]
        self.indptr, self.indices = indptr.astype(np.int32), indices.astype(np.int32)
        self.nnz = len(indices)
        # a spring's node entries (a, b) come in cell order (0,0), (0,1), (1,0), (1,1)
        self.slots = np.ascontiguousarray(at[:4 * s].reshape(s, 4, d * d)[:, [0, 3, 1, 2]]
                                          .transpose(1, 0, 2))
        self._inv = np.concatenate([self.slots.reshape(-1), self.diag]).astype(np.intp)
        self._zero_tail = np.zeros(ndof)

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
