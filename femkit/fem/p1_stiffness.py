"""P1 stiffness matrix ``K_ij = sum_e kappa_e |T_e| grad N_i . grad N_j``.

With ``e_a`` the edge of triangle T opposite vertex ``a``, ``grad N_a = rot(e_a) / (2 A)``,
so the local matrix is ``kappa_e (e_a . e_b) / (4 |T_e|)``: computed for all elements at once
as an (m, 3, 3) array and summed into CSR through a cached :class:`SparsityPattern`.
On tetrahedra ``grad N_a = g_a / D`` with ``g_1 = b x c``, ``g_2 = c x a``, ``g_3 = a x b``
(``a, b, c`` the edges from vertex 0, ``D = 6 V``) and ``g_0 = -(g_1 + g_2 + g_3)``, so the
local matrix is ``kappa_e (g_a . g_b) / (6 |D|)``, (m, 4, 4).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> assemble_stiffness(m).toarray().tolist()
[[1.0, -0.5, -0.5], [-0.5, 0.5, 0.0], [-0.5, 0.0, 0.5]]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._elements import check_areas, select_elements, tetrahedron_geometry
from .coefficients import Coefficient, element_coefficient
from ..errors import InputError
from .sparsity import NUMBA_THRESHOLD, SparsityPattern
from ..warmup_registry import register_kernels, register_threshold

register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("P1 assembly", "femkit.fem._kernels", "_stiffness", "_stiffness_tet", rank=1)
register_kernels("P1 assembly", "femkit.fem._one_off_stiffness", "_cell_rows", "_triangle_values", "_edge_pattern",
                 "_edge_values", "_edge_fill", rank=1)
register_kernels("P1 assembly", "femkit.fem._one_off_stiffness", "_tet_values", rank=1, tetrahedra_only=True)


def local_stiffness(mesh, kappa: Coefficient = 1.0, *, elements=None) -> np.ndarray:
    """Local P1 stiffness matrices of the selected elements, shape (k, 3, 3) (triangles) or
    (k, 4, 4) (tetrahedra).

    Raises :class:`~femkit.errors.InputError` for a non-positive or non-finite ``kappa`` and
    :class:`~femkit.errors.DegenerateMeshError` for zero-area triangles / zero-volume tetrahedra.
    """
    idx = select_elements(mesh, elements)
    if mesh.dim == 3:
        grads, volume, _, _ = tetrahedron_geometry(mesh, idx)
        scale = element_coefficient(mesh, kappa, idx) * volume
        return np.einsum("mad,mbd->mab", grads, grads) * scale[:, None, None]
    ex, ey, area = edge_components(mesh, idx)
    scale = element_coefficient(mesh, kappa, idx) / (4.0 * area)
    local = np.empty((len(area), 3, 3))
    for a in range(3):  # 6 distinct dot products e_a . e_b per element, each an (m,) array
        for b in range(a, 3):
            v = ex[a] * ex[b]
            v += ey[a] * ey[b]
            v *= scale
            local[:, a, b] = v
            if b != a:
                local[:, b, a] = v
    return local


def _kernel_coefficient(mesh, kappa, idx):
    """A valid scalar kappa as a float (the kernel broadcasts it), else per-element values."""
    if isinstance(kappa, (int, float, np.floating, np.integer)) and not isinstance(kappa, bool):
        val = float(kappa)
        if np.isfinite(val) and val > 0:
            return val
    return element_coefficient(mesh, kappa, idx)  # validates (raises with the reason)


def edge_components(mesh, idx):
    """x and y components of the edges opposite each vertex (3 arrays each) and the areas."""
    tri = mesh.triangles if idx is None else mesh.triangles[idx]
    px, py = mesh.points[:, 0].copy(), mesh.points[:, 1].copy()
    x = [np.take(px, tri[:, a]) for a in range(3)]
    y = [np.take(py, tri[:, a]) for a in range(3)]
    ex = [x[2] - x[1], x[0] - x[2], x[1] - x[0]]
    ey = [y[2] - y[1], y[0] - y[2], y[1] - y[0]]
    area = 0.5 * np.abs(ex[2] * ey[0] - ey[2] * ex[0])
    check_areas(area, idx)
    return ex, ey, area


def assemble_stiffness(mesh, kappa: Coefficient = 1.0, *, elements=None,
                       pattern: SparsityPattern | None = None, backend: str = "auto",
                       keep_pattern: bool = True) -> sp.csr_matrix:
    """Assemble the global P1 stiffness matrix of ``-div(kappa grad u)``.

    Parameters
    ----------
    mesh : Mesh
    kappa : float, (m,) array, dict {cell tag or name: value} or callable kappa(x, y[, z])
        Diffusion coefficient, constant per element (callables are evaluated at barycentres).
    elements : index array or boolean mask, optional
        Assemble only these elements (a partition); the result keeps the global shape, so the
        matrices of a partition of the elements sum to the full matrix.
    pattern : SparsityPattern, optional
        A pattern built for this mesh; by default the mesh's cached pattern is used.
    backend : {"auto", "numpy", "numba"}
        ``numpy``: (m, w, w) local matrices + ``np.bincount``; ``numba``: one fused compiled
        loop (imported lazily, cached on disk); ``auto``: numba from
        :data:`~femkit.fem.sparsity.NUMBA_THRESHOLD` selected elements on.  A first numba
        assembly of the whole mesh without a cached pattern builds the pattern and sums the
        matrix in the same compiled pass (:meth:`SparsityPattern.with_stiffness`) and caches
        the pattern for later calls.
    keep_pattern : bool
        ``False``: a whole-mesh numba assembly without a cached pattern builds the matrix's
        rows from a node -> element incidence list, then adds each element's geometry once
        (:func:`femkit.fem._one_off_stiffness.stiffness_rows_kernel`: the same matrix bit for bit)
        and caches nothing, so no (m, 9) or (m, 16) int slot map is ever allocated (the one-off
        assembly of a large run: a third of the memory of the fused pass).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        Symmetric, sorted indices, the full P1 pattern.
    """
    if backend not in ("auto", "numpy", "numba"):
        raise InputError(f"unknown assembly backend {backend!r}; valid: auto, numba, numpy")
    idx = select_elements(mesh, elements)
    count = mesh.n_cells if idx is None else len(idx)
    if backend == "auto":
        backend = "numba" if count >= NUMBA_THRESHOLD else "numpy"
    if pattern is None:
        pattern = SparsityPattern.cached(mesh)
        if pattern is None and backend == "numba" and idx is None and not keep_pattern:
            from ._one_off_stiffness import stiffness_rows_kernel

            arrays = stiffness_rows_kernel(mesh, _kernel_coefficient(mesh, kappa, None))
            if arrays is not None:
                indptr, indices, data = arrays
                K = sp.csr_matrix((data, indices, indptr.astype(indices.dtype, copy=False)),
                                  shape=(mesh.n_points, mesh.n_points), copy=False)
                K.has_sorted_indices = True
                return K
        if pattern is None and backend == "numba" and idx is None:
            # first assembly on a large mesh: pattern, slots and stiffness in one pass
            pattern, data = SparsityPattern.with_stiffness(mesh, _kernel_coefficient(mesh, kappa, None))
            if data is not None:
                return pattern.matrix(data)
        if pattern is None:
            pattern = SparsityPattern.for_mesh(mesh)
    else:
        pattern.check(mesh)
    if backend == "numba":
        from ._kernels import stiffness_kernel

        data = stiffness_kernel(mesh, idx, _kernel_coefficient(mesh, kappa, idx), pattern)
        if data is not None:
            return pattern.matrix(data)
    local = local_stiffness(mesh, kappa, elements=idx)
    return pattern.assemble(local, elements=idx)
