"""The CSR pattern of a vector matrix (``d x d`` blocks per node pair), built once per mesh.

The node-level pattern (which node pairs share an element: P1 vertices, or P2's six or ten
nodes) is femkit's one assembly pattern, :meth:`femkit.fem.sparsity.SparsityPattern.from_cells`
(its CSR structure and the slot of each element's node pair), and every node pair
becomes a dense ``d x d`` block of the dof-level CSR matrix (dof ``i*d + a``, node-major as the
dynamics' state arrays). Row ``r*d + a`` starts at ``d^2 indptr[r] + a d w_r`` (``w_r`` = number
of node columns in node row ``r``), and the block of node column position ``p`` occupies
columns ``p d .. p d + d - 1`` of it: so the element pass needs only the node-pair slot map
``node_slots (m, (d+1)^2)``, not a dof-level map (16x smaller for tetrahedra).

>>> import numpy as np
>>> pat = BlockPattern(np.array([[0, 1, 2]]), 3, 2)
>>> pat.nnz, pat.shape
(36, (6, 6))
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["BlockPattern"]


class BlockPattern:
    """Dof-level CSR pattern of a vector matrix and the node-pair slots of each element.

    Parameters
    ----------
    cells : (m, k) int array: each element's nodes (``k = d + 1`` for P1, 6 or 10 for P2).
    n : number of nodes.
    dim : ``d``.

    Attributes
    ----------
    node_indptr : (n+1,) int64, node-level CSR row pointer.
    node_slots : (m, k^2) int64, node-level data position of entry ``(cells[e,p], cells[e,q])``
        at ``p k + q``.
    indptr, indices : the dof-level CSR structure (sorted columns; int32 when it fits).
    """

    def __init__(self, cells: np.ndarray, n: int, dim: int):
        from ..fem.sparsity import SparsityPattern

        cells = np.asarray(cells, dtype=np.int64)
        d = dim
        node = SparsityPattern.from_cells(cells, n)
        ip = node.indptr.astype(np.int64)
        ncol = node.indices.astype(np.int64)
        width = np.diff(ip)
        self.node_indptr = ip
        self.node_slots = np.ascontiguousarray(node.slots, dtype=np.int64)
        self.n, self.dim, self.ndof = n, d, n * d
        self.nnz = int(len(ncol) * d * d)
        # dof rows: node row r, component a -> its node columns, each expanded to d columns
        row_len = np.repeat(width * d, d)
        indptr = np.zeros(n * d + 1, dtype=np.int64)
        np.cumsum(row_len, out=indptr[1:])
        starts = ip[:-1]
        # entry order inside node row r: component a, then the node columns p of r, then c
        r_of = np.repeat(np.arange(n), width * d * d)
        local = np.arange(self.nnz) - (d * d * ip[:-1])[r_of]
        row_width = (d * width)[r_of]
        pos_in_row = local % row_width
        p, c = pos_in_row // d, pos_in_row % d
        node_cols = ncol
        idx = node_cols[ip[:-1][r_of] + p] * d + c
        itype = np.int32 if self.nnz < np.iinfo(np.int32).max else np.int64
        self.indptr = indptr.astype(itype)
        self.indices = idx.astype(itype)
        self.shape = (n * d, n * d)

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with these values (index arrays copied, so it owns them)."""
        mat = sp.csr_matrix((data, self.indices.copy(), self.indptr.copy()), shape=self.shape)
        mat.has_sorted_indices = True
        return mat
