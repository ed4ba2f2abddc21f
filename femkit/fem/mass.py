"""Mass matrices ``M_ij = int rho phi_i phi_j``, consistent and lumped, P1 and P2.

Lumping:

- **P1**: the row sums (``|T| rho / (d + 1)`` to each vertex), positive on every mesh.
- **P2**: row sums are useless for P2 (a vertex function integrates to 0 on a triangle and to
  ``-|T| / 20`` on a tetrahedron: zero or negative masses), so P2 is lumped by **HRZ diagonal
  scaling** (Hinton, Rock & Zienkiewicz 1976, "A note on mass lumping and related processes in
  the finite element method", Earthquake Eng. Struct. Dyn. 4): each cell's consistent diagonal
  scaled so that it sums to the cell's mass ``rho |T|``. The consistent diagonal is positive, so
  every lumped entry is: on a triangle a vertex gets ``3/57`` of the cell's mass and an edge
  ``16/57``; on a tetrahedron ``1/36`` and ``4/27`` (for P1, HRZ equals the row sums).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> mass_matrix(m).toarray().round(6).tolist()[0]
[0.083333, 0.041667, 0.041667]
>>> mass_matrix(m, element="P2", lumped=True).diagonal().round(6).tolist()
[0.026316, 0.026316, 0.026316, 0.140351, 0.140351, 0.140351]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..elements import get_element
from ._elements import cell_measures, select_elements
from .coefficients import element_coefficient
from .dofs import dof_map
from .forms import assemble_matrix, reference_mass

__all__ = ["mass_matrix", "lumping_weights"]


def lumping_weights(element) -> np.ndarray:
    """(n,) share of a cell's mass ``rho |T|`` that lumping gives each local dof: row sums for
    P1, the HRZ-scaled consistent diagonal for higher degrees (all positive)."""
    R = reference_mass(element)
    if element.degree == 1:
        return R.sum(axis=1)
    diag = np.diag(R)
    return diag / diag.sum()


def mass_matrix(mesh, *, element: str = "P1", lumped: bool = False, density=None,
                elements=None) -> sp.csr_matrix:
    """The mass matrix of ``element`` on ``mesh``.

    Parameters
    ----------
    mesh : Mesh
    element : {"P1", "P2"}
        Element name (:data:`femkit.elements.ELEMENTS`); dofs numbered by
        :func:`femkit.fem.dofs.dof_map` (vertices, then edges).
    lumped : bool
        A diagonal matrix: P1 row sums, P2 HRZ diagonal scaling (module docstring), positive.
    density : float, (m,) array, dict {tag or name: value} or callable, optional
        ``rho``, constant per cell (default 1).
    elements : index array or boolean mask, optional
        Only these cells (the result keeps the global shape).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_dofs, n_dofs)
        Symmetric positive definite (consistent) or positive diagonal (lumped).
    """
    rho = 1.0 if density is None else density
    if not lumped:
        return assemble_matrix(mesh, "mass", rho, element=element, elements=elements)
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    idx = select_elements(mesh, elements)
    vol, _ = cell_measures(mesh, idx)
    cell_mass = element_coefficient(mesh, rho, idx) * vol
    cells = dofs.cells if idx is None else dofs.cells[idx]
    weights = lumping_weights(elem)
    diag = np.bincount(cells.ravel(), weights=(cell_mass[:, None] * weights).ravel(),
                       minlength=dofs.n_dofs)
    return sp.diags(diag, format="csr")
