"""P1 stiffness matrix ``K_ij = sum_e kappa_e |T_e| grad N_i . grad N_j``.

With ``e_a`` the edge of triangle T opposite vertex ``a``, ``grad N_a = rot(e_a) / (2 A)``,
so the local matrix is ``kappa_e (e_a . e_b) / (4 |T_e|)``: computed for all elements at once
as an (m, 3, 3) array and summed into CSR through a cached :class:`SparsityPattern`.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> assemble_stiffness(m).toarray().tolist()
[[1.0, -0.5, -0.5], [-0.5, 0.5, 0.0], [-0.5, 0.0, 0.5]]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._elements import select_elements, triangle_geometry
from .coefficients import Coefficient, element_coefficient
from .sparsity import SparsityPattern


def local_stiffness(mesh, kappa: Coefficient = 1.0, *, elements=None) -> np.ndarray:
    """Local P1 stiffness matrices of the selected elements, shape (k, 3, 3).

    Raises :class:`~femkit.errors.InputError` for a non-positive or non-finite ``kappa`` and
    :class:`~femkit.errors.DegenerateMeshError` for zero-area triangles.
    """
    idx = select_elements(mesh, elements)
    e, area, _, _ = triangle_geometry(mesh, idx)
    kap = element_coefficient(mesh, kappa, idx)
    scale = kap / (4.0 * area)
    ex, ey = e[:, :, 0], e[:, :, 1]
    # (k,3,1)*(k,1,3): all 9 dot products e_a . e_b, scaled per element
    local = ex[:, :, None] * ex[:, None, :]
    local += ey[:, :, None] * ey[:, None, :]
    local *= scale[:, None, None]
    return local


def assemble_stiffness(mesh, kappa: Coefficient = 1.0, *, elements=None,
                       pattern: SparsityPattern | None = None) -> sp.csr_matrix:
    """Assemble the global P1 stiffness matrix of ``-div(kappa grad u)``.

    Parameters
    ----------
    mesh : Mesh
    kappa : float, (m,) array, dict {cell tag or name: value} or callable kappa(x, y)
        Diffusion coefficient, constant per element (callables are evaluated at barycentres).
    elements : index array or boolean mask, optional
        Assemble only these elements (a partition); the result keeps the global shape, so the
        matrices of a partition of the elements sum to the full matrix.
    pattern : SparsityPattern, optional
        A pattern built for this mesh; by default the mesh's cached pattern is used.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        Symmetric, sorted indices, the full P1 pattern.
    """
    if pattern is None:
        pattern = SparsityPattern.for_mesh(mesh)
    else:
        pattern.check(mesh)
    idx = select_elements(mesh, elements)
    local = local_stiffness(mesh, kappa, elements=idx)
    return pattern.assemble(local, elements=idx)
