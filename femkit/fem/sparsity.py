"""The CSR sparsity pattern of finite-element assembly, computed once per mesh and reused.

This is femkit's one assembly stack: a :class:`SparsityPattern` holds ``indptr`` and ``indices``
of the global matrix and ``slots`` (m, w * w): the position in CSR ``data`` of each local entry
``(e, a, b)`` (row ``cells[e, a]``, column ``cells[e, b]``, flattened as ``w a + b``).  Assembling
a new set of local matrices on the same cells is then one ``np.bincount`` (:meth:`assemble`);
Dirichlet elimination is :func:`femkit.fem.dirichlet.apply_dirichlet` (a compiled pass from its
threshold on).

- P1 on a mesh: ``w`` = 3 for triangles, 4 for tetrahedra (:meth:`SparsityPattern.for_mesh`,
  cached; the P1 stiffness may fill the pattern and its values in one compiled pass).
- Any dofs per cell and any block size: :meth:`SparsityPattern.from_cells` with a dof map's
  cells (P2: 6 or 10 per cell, :mod:`femkit.fem.dofs`) and ``block=b`` for vector fields (dof
  ``b i + c`` is component ``c`` of node ``i``, node-major; local entries ordered the same way,
  so ``w = b * dofs per cell``); :func:`pattern_for` caches one per mesh, element and block
  (one component on a large mesh: built row by row from the dof map,
  :func:`femkit.fem._element_kernels.element_pattern_kernel`).
- Node pairs as dense ``d x d`` blocks addressed by node-pair slots: :class:`BlockPattern` (an
  elastic body's Hessian, :mod:`femkit.solids`), :func:`block_structure`, :func:`block_positions`.
- The mass-spring matrices (:class:`femkit.dynamics.forces.jacobian.SpringPattern`,
  :class:`femkit.dynamics.kernels.assembly.FreePattern`) from the same parts: the node pairs of
  entry sets (springs as 2-node cells, :func:`cell_entries`; :func:`entry_pattern`) as blocks, a
  force's fixed CSR structure joined by :func:`union_structures`, the held dofs dropped with a
  slot map by :func:`restrict_structure` (the pattern of Dirichlet elimination's
  ``K[free][:, free]``, whose values :func:`~femkit.fem.dirichlet.apply_dirichlet` moves in one
  pass with the lifting).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), np.array([[0, 1, 2], [0, 2, 3]]))
>>> pat = SparsityPattern.from_mesh(m)
>>> pat.nnz, pat.indptr.tolist()
(14, [0, 4, 7, 11, 14])
>>> pat.assemble(np.ones((2, 3, 3))).toarray().astype(int).tolist()
[[2, 1, 2, 1], [1, 1, 1, 0], [2, 1, 2, 1], [1, 0, 1, 1]]
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ._elements import select_elements
from ..warmup_registry import register_kernels, register_threshold

#: Meshes with at least this many triangles use the compiled (numba) pattern builder
#: under ``backend="auto"``; below it numpy's sort is fast enough and no compile is paid.
NUMBA_THRESHOLD = 200_000
register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("P1 assembly", "femkit.fem._kernels", "_incidences", "_pattern", "_pattern_cells", rank=1)
# the element-generic assembly's (femkit.fem.forms, not imported by the P1 pipeline; its kernels are
# declared with the stack's pattern so that the warm-up, which compiles them, knows them)
register_kernels("P1 assembly", "femkit.fem._kernels", "_scatter", "_element_stiffness", rank=1)
register_kernels("P1 assembly", "femkit.fem._element_kernels", "_element_pattern", "_stiffness_rows",
                 "_cell_metric", "_element_stiffness", "_quadrature_coordinates", "_element_load", rank=1)

def compiled_from(count: int, element) -> bool:
    """True when ``count`` cells of ``element`` (an :class:`~femkit.elements.base.Element`) go
    through the compiled passes: P1 from :data:`NUMBA_THRESHOLD` cells on, any other element
    from as many local-matrix entries (P2: a quarter of the cells in 2D, 16 % in 3D), so that a
    P2 mesh of 190k triangles is not left on the NumPy path at 7x the compiled cost."""
    if element.name == "P1":
        return count >= NUMBA_THRESHOLD
    return count * element.n_dofs ** 2 >= NUMBA_THRESHOLD * (element.dim + 1) ** 2


_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_ELEMENT_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class SparsityPattern:
    """CSR structure of the matrices of one set of cells (a P1 mesh, a dof map) plus the
    local-entry -> slot map.

    Attributes
    ----------
    n : int
        Matrix size (number of mesh points).
    indptr, indices : ndarray
        CSR structure with sorted column indices (int32 when it fits).
    slots : ndarray, shape (m, w * w)
        ``slots[e, w a + b]`` is the index into CSR ``data`` of entry
        ``(cells[e, a], cells[e, b])`` (int32 from the compiled builder when the
        entry count fits, else int64).
    """

    n: int
    indptr: np.ndarray
    indices: np.ndarray
    slots: np.ndarray

    @property
    def nnz(self) -> int:
        return int(self.indices.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.slots.shape[0])

    @classmethod
    def from_mesh(cls, mesh, *, backend: str = "auto") -> "SparsityPattern":
        """Build the pattern of ``mesh``.

        Parameters
        ----------
        backend : {"auto", "numpy", "numba"}
            ``numpy``: ``np.unique`` over the 9 m (row, col) keys; ``numba``: a compiled
            O(m) counting-sort kernel (imported lazily, cached on disk);
            ``auto``: numba for meshes of at least :data:`NUMBA_THRESHOLD` cells.
        """
        return cls.from_cells(mesh.cells, mesh.n_points, backend=backend)

    @classmethod
    def _from_arrays(cls, n, indptr, indices, slots) -> "SparsityPattern":
        idx_dtype = np.int32 if max(len(indices), n) < np.iinfo(np.int32).max else np.int64
        return cls(n, indptr.astype(idx_dtype, copy=False), indices.astype(idx_dtype, copy=False), slots)

    @classmethod
    def with_stiffness(cls, mesh, kappa) -> "tuple[SparsityPattern, np.ndarray | None]":
        """Build (and cache) the pattern of ``mesh`` and the CSR data of its stiffness matrix
        for ``kappa`` (a float or one value per element) in one compiled pass.

        This is the first assembly on a large mesh: the element-order pass that writes the
        slot map sums the local matrices too (triangles and tetrahedra).  ``data`` is None if
        an element is degenerate.
        """
        from ._kernels import pattern_kernel

        indptr, indices, slots, data = pattern_kernel(mesh.cells, mesh.n_points, mesh.points, kappa)
        pat = cls._from_arrays(mesh.n_points, indptr, indices, slots)
        _CACHE[mesh] = pat
        return pat, data

    @classmethod
    def cached(cls, mesh) -> "SparsityPattern | None":
        """The cached pattern of ``mesh``, or None if none was built yet."""
        return _CACHE.get(mesh)

    @classmethod
    def for_mesh(cls, mesh) -> "SparsityPattern":
        """The pattern of ``mesh``, built on first use and cached while the mesh lives."""
        pat = _CACHE.get(mesh)
        if pat is None:
            pat = cls.from_mesh(mesh)
            _CACHE[mesh] = pat
        return pat

    @classmethod
    def from_cells(cls, cells: np.ndarray, n: int, *, block: int = 1,
                   backend: str = "auto") -> "SparsityPattern":
        """The pattern of local dofs ``cells`` (m, k) among ``n`` global ones, each dof a block of
        ``block`` components (node-major: global dof ``block * i + c``).

        Parameters
        ----------
        cells : (m, k) int array
            Global dof (or node) numbers of each cell's local dofs (a :class:`~femkit.fem.dofs.DofMap`'s
            ``cells``).
        n : int
            Number of global dofs (nodes) before blocking; the matrix is ``n * block`` square.
        block : int
            Components per dof; local matrices are then ``(k * block)`` square, row ``block a + c``
            for component ``c`` of local dof ``a``.
        backend : {"auto", "numpy", "numba"}
            As :meth:`from_mesh` (the compiled builder works for any ``k``).
        """
        if block < 1:
            raise InputError(f"block size must be a positive integer, got {block}")
        if block > 1:
            cells = np.asarray(cells, dtype=np.int64)
            cells = (cells[:, :, None] * block + np.arange(block)).reshape(len(cells), -1)
        size = int(n) * block
        if backend == "auto":
            backend = "numba" if len(cells) >= NUMBA_THRESHOLD else "numpy"
        if backend == "numpy":
            indptr, indices, slots = _pattern_numpy(cells, size)
        elif backend == "numba":
            from ._kernels import pattern_kernel

            indptr, indices, slots, _ = pattern_kernel(cells, size)
        else:
            raise InputError(f"unknown sparsity backend {backend!r}; valid: auto, numba, numpy")
        return cls._from_arrays(size, indptr, indices, slots)

    def check(self, mesh) -> None:
        """Raise :class:`InputError` if this pattern does not belong to ``mesh``'s size."""
        width = int(round(np.sqrt(self.slots.shape[1]))) if self.slots.ndim == 2 else 3
        if self.n != mesh.n_points or self.n_elements != mesh.n_cells or width != mesh.dim + 1:
            raise InputError(
                f"sparsity pattern is for {self.n} nodes / {self.n_elements} cells of "
                f"{width} nodes, mesh has {mesh.n_points} / {mesh.n_cells} of {mesh.dim + 1}"
            )

    def assemble(self, local: np.ndarray, elements=None) -> sp.csr_matrix:
        """Sum local matrices into a global CSR matrix.

        Parameters
        ----------
        local : ndarray, shape (k, w, w) or (k, w * w)
            Local matrices of the selected elements (all ``m`` when ``elements`` is None).
        elements : index array or boolean mask, optional
            Which elements ``local`` belongs to; the result still has the global shape and
            the full pattern (entries outside the subset are stored zeros).
        """
        idx = None if elements is None else _normalise(self, elements)
        slots = self.slots if idx is None else self.slots[idx]
        local = np.asarray(local, dtype=np.float64).reshape(len(slots), self.slots.shape[1])
        return self.matrix(np.bincount(slots.ravel(), weights=local.ravel(), minlength=self.nnz))

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """A CSR matrix with this pattern and ``data`` (index arrays copied, so it owns them)."""
        mat = sp.csr_matrix((data, self.indices.copy(), self.indptr.copy()),
                            shape=(self.n, self.n), copy=False)
        mat.has_sorted_indices = True
        return mat


class BlockPattern:
    """Dof-level CSR pattern of a vector matrix (a ``d x d`` block per node pair sharing a cell:
    an elastic body's Hessian) and the node-pair slots of each cell.

    The node-level pattern is :meth:`SparsityPattern.from_cells`'s, expanded by
    :func:`block_structure`: the element pass needs only the node-pair slot map
    ``node_slots (m, k^2)``, not a dof-level one (16x smaller for tetrahedra).

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

    >>> pat = BlockPattern(np.array([[0, 1, 2]]), 3, 2)
    >>> pat.nnz, pat.shape
    (36, (6, 6))
    """

    def __init__(self, cells: np.ndarray, n: int, dim: int):
        node = SparsityPattern.from_cells(np.asarray(cells, dtype=np.int64), n)
        self.node_indptr = node.indptr.astype(np.int64)
        self.node_slots = np.ascontiguousarray(node.slots, dtype=np.int64)
        self.n, self.dim, self.ndof = n, dim, n * dim
        self.nnz = int(node.nnz * dim * dim)
        self.indptr, self.indices = block_structure(node.indptr, node.indices, dim)
        self.shape = (n * dim, n * dim)

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with these values (index arrays copied, so it owns them)."""
        mat = sp.csr_matrix((data, self.indices.copy(), self.indptr.copy()), shape=self.shape)
        mat.has_sorted_indices = True
        return mat


def pattern_for(mesh, dofs, block: int = 1) -> SparsityPattern:
    """The pattern of a dof map ``dofs`` (:func:`femkit.fem.dofs.dof_map`) on ``mesh`` with
    ``block`` components per dof, built on first use and cached while the mesh lives (P1 with
    ``block=1`` is the mesh's own cached P1 pattern, :meth:`SparsityPattern.for_mesh`)."""
    if dofs.element.name == "P1" and block == 1:
        return SparsityPattern.for_mesh(mesh)
    per_mesh = _ELEMENT_CACHE.setdefault(mesh, {})
    key = (dofs.element.name, int(block))
    pat = per_mesh.get(key)
    if pat is None:
        if block == 1 and compiled_from(len(dofs.cells), dofs.element):  # row by row from the dof map
            from ._element_kernels import element_pattern_kernel

            pat = SparsityPattern._from_arrays(dofs.n_dofs, *element_pattern_kernel(dofs.cells, dofs.n_dofs))
        else:
            pat = SparsityPattern.from_cells(dofs.cells, dofs.n_dofs, block=block)
        per_mesh[key] = pat
    return pat


def cached_pattern(mesh, dofs, block: int = 1) -> "SparsityPattern | None":
    """The pattern :func:`pattern_for` would return if it is built already, else None."""
    if dofs.element.name == "P1" and block == 1:
        return SparsityPattern.cached(mesh)
    return _ELEMENT_CACHE.get(mesh, {}).get((dofs.element.name, int(block)))


def _normalise(pattern: SparsityPattern, elements):
    class _Shape:  # select_elements only needs n_cells
        n_cells = pattern.n_elements

    return select_elements(_Shape, elements)


def cell_entries(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of every local entry of ``cells`` (m, w), in slot order: entry
    ``(e, w a + b)`` at ``e w^2 + w a + b``, row ``cells[e, a]``, column ``cells[e, b]``; int64.

    >>> [r.tolist() for r in cell_entries(np.array([[2, 0]]))]
    [[2, 2, 0, 0], [2, 0, 2, 0]]
    """
    cells = np.asarray(cells, dtype=np.int64)
    w = cells.shape[1]
    return np.repeat(cells, w, axis=1).ravel(), np.tile(cells, (1, w)).ravel()


def structure_entries(indptr: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of every stored entry of a CSR structure, in storage order; int64."""
    indptr = np.asarray(indptr, dtype=np.int64)
    rows = np.repeat(np.arange(len(indptr) - 1, dtype=np.int64), np.diff(indptr))
    return rows, np.asarray(indices, dtype=np.int64)


def entry_pattern(rows: np.ndarray, cols: np.ndarray,
                  n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The CSR pattern of the entries ``(rows[k], cols[k])`` among ``n`` dofs (repeats allowed)
    and the slot of each entry in its ``data``.

    Several entry sets (cells of different widths, :func:`cell_entries`; a CSR structure,
    :func:`structure_entries`) share one pattern when their rows and columns are concatenated;
    each set's slots are then its part of ``slots``.

    Returns
    -------
    indptr, indices : int64, sorted columns.
    slots : (len(rows),) int64.

    >>> indptr, indices, slots = entry_pattern(np.array([0, 2, 0, 1]), np.array([2, 0, 2, 1]), 3)
    >>> indptr.tolist(), indices.tolist(), slots.tolist()
    ([0, 1, 2, 3], [2, 1, 0], [0, 2, 0, 1])
    """
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    n = int(n)
    uniq, inv = np.unique(rows * np.int64(n) + cols, return_inverse=True)
    indptr = np.zeros(n + 1, dtype=np.int64)
    if n:
        np.cumsum(np.bincount(uniq // n, minlength=n), out=indptr[1:])
    return indptr, (uniq % n if n else uniq), inv.reshape(-1)


def block_structure(indptr: np.ndarray, indices: np.ndarray,
                    block: int) -> tuple[np.ndarray, np.ndarray]:
    """The dof-level CSR structure of a node-level pattern whose every entry is a dense
    ``block x block`` block (dof ``block i + c``, node-major; columns sorted).

    Row ``block r + p`` starts at ``block^2 indptr[r] + p block w_r`` (``w_r``: node columns of node
    row ``r``) and the block of the node entry at position ``t`` of row ``r`` occupies its columns
    ``(t - indptr[r]) block ..`` (:func:`block_positions`), so a node-pair slot map addresses the
    dof-level ``data`` without a dof-level map.

    >>> ip, ix = block_structure(np.array([0, 1, 3]), np.array([1, 0, 1]), 2)
    >>> ip.tolist(), ix.tolist()
    ([0, 2, 4, 8, 12], [2, 3, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3])
    """
    ip = np.asarray(indptr, dtype=np.int64)
    d, n = int(block), len(ip) - 1
    # node row r's dof columns, ascending, are seg[d ip[r] : d ip[r + 1]]; each of its d dof rows
    # holds them all
    seg = (np.asarray(indices, dtype=np.int64)[:, None] * d + np.arange(d)).ravel()
    row_len = np.repeat(np.diff(ip) * d, d)
    out = np.zeros(n * d + 1, dtype=np.int64)
    np.cumsum(row_len, out=out[1:])
    nnz = int(out[-1])
    cols = seg[np.arange(nnz) - np.repeat(out[:-1] - np.repeat(d * ip[:-1], d), row_len)]
    itype = np.int32 if nnz < np.iinfo(np.int32).max else np.int64
    return out.astype(itype), cols.astype(itype)


def block_positions(indptr: np.ndarray, node_slots: np.ndarray, node_rows: np.ndarray,
                    block: int) -> np.ndarray:
    """``(k, block^2)`` positions in the :func:`block_structure` ``data`` of entry ``(p, q)`` (at
    ``p block + q``) of the blocks of node entries: ``node_slots`` their slots in the node-level
    pattern ``indptr``, ``node_rows`` their node rows.

    >>> block_positions(np.array([0, 1, 3]), np.array([2]), np.array([1]), 2).tolist()
    [[6, 7, 10, 11]]
    """
    ip = np.asarray(indptr, dtype=np.int64)
    d = int(block)
    rows = np.asarray(node_rows, dtype=np.int64)
    start = ip[rows]
    base = d * d * start + (np.asarray(node_slots, dtype=np.int64) - start) * d
    e = np.arange(d * d)
    return base[:, None] + (e // d) * (d * (ip[rows + 1] - start))[:, None] + e % d


def union_structures(structures, n: int) -> tuple[np.ndarray, np.ndarray, list]:
    """The union of CSR structures ``[(indptr, indices), ...]`` (each ``n x n``, distinct columns
    in each row) and, for each, the position of every one of its entries in the union's ``data``.

    The entries are merged by a stable sort of their ``(row, column)`` keys: linear for
    structures with sorted columns, whose keys are sorted runs; one structure (sorted) is its own
    union.

    Returns
    -------
    indptr, indices : int64, sorted columns.
    positions : list of int64 arrays, one per structure, in its storage order.

    >>> ip, ix, (p, q) = union_structures([(np.array([0, 1, 2]), np.array([0, 1])),
    ...                                    (np.array([0, 1, 1]), np.array([1]))], 2)
    >>> ip.tolist(), ix.tolist(), p.tolist(), q.tolist()
    ([0, 2, 3], [0, 1, 1], [0, 2], [1])
    """
    n = int(n)
    if len(structures) == 1:
        indptr, indices = (np.asarray(a, dtype=np.int64) for a in structures[0])
        return indptr, indices, [np.arange(len(indices))]
    keys = [rows * np.int64(n) + cols for rows, cols in (structure_entries(*st) for st in structures)]
    every = np.concatenate(keys)
    order = np.argsort(every, kind="stable")
    ordered = every[order]
    first = np.ones(len(every), dtype=bool)
    first[1:] = ordered[1:] != ordered[:-1]
    where = np.empty(len(every), dtype=np.int64)
    where[order] = np.cumsum(first) - 1
    uniq = ordered[first]
    indptr = np.zeros(n + 1, dtype=np.int64)
    if n:
        np.cumsum(np.bincount(uniq // n, minlength=n), out=indptr[1:])
    return indptr, (uniq % n if n else uniq), np.split(where, np.cumsum([len(k) for k in keys])[:-1])


def restrict_structure(indptr: np.ndarray, indices: np.ndarray,
                       keep: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A CSR structure restricted to the rows and columns ``keep`` (sorted), renumbered in order
    (``keep[r]`` becomes ``r``: the free-dof matrix of a system with held dofs, the pattern of
    Dirichlet elimination's ``K[free][:, free]``), and ``moved``: each old entry's position in the
    restricted ``data``, -1 for an entry left out.

    >>> ip, ix, moved = restrict_structure(np.array([0, 2, 3, 5]), np.array([0, 2, 1, 0, 2]), np.array([0, 2]))
    >>> ip.tolist(), ix.tolist(), moved.tolist()
    ([0, 2, 4], [0, 1, 0, 1], [0, 1, -1, 2, 3])
    """
    ip = np.asarray(indptr, dtype=np.int64)
    n, nk = len(ip) - 1, len(keep)
    renumber = np.full(n, -1, dtype=np.int64)
    renumber[keep] = np.arange(nk)
    rows = renumber[np.repeat(np.arange(n), np.diff(ip))]
    cols = renumber[np.asarray(indices, dtype=np.int64)]
    inside = (rows >= 0) & (cols >= 0)
    moved = np.full(len(cols), -1, dtype=np.int64)
    moved[inside] = np.arange(int(inside.sum()))
    out = np.zeros(nk + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows[inside], minlength=nk), out=out[1:])
    return out, cols[inside], moved


def _pattern_numpy(cells: np.ndarray, n: int):
    indptr, indices, slots = entry_pattern(*cell_entries(cells), n)
    return indptr, indices, slots.reshape(len(cells), -1).astype(np.intp, copy=False)
