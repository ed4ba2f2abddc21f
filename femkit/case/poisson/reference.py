"""The scikit-fem reference of the Poisson problem (P1, P2): the one place femkit calls scikit-fem.

``femkit check`` (:mod:`femkit.case.poisson.cross_check`) and the convergence study's reference
rows (:mod:`femkit.study.poisson_convergence.run`) assemble, condense and solve the same problem with
scikit-fem (Gustafsson & McBain, "scikit-fem: A Python package for finite element assembly",
JOSS 2020) through these functions, on femkit's own mesh (points and cells in femkit's order;
triangles or tetrahedra):

* :func:`assemble` -> ``(K, F)``: stiffness with a per-element ``kappa`` and the load of a
  source ``f(x, y)``, with scikit-fem's default quadrature for P1 or, given ``rule``, one of
  femkit's quadrature rules (:mod:`femkit.fem.quadrature`) handed to scikit-fem's ``Basis``:
  the same points and weights as femkit's load with that rule;
  ``element="P2"`` uses ``ElementTriP2`` / ``ElementTetP2`` and returns ``K``, ``F`` in
  femkit's dof order (:func:`femkit_order`: vertices, then edges as :func:`femkit.fem.dofs.dof_map`);
* :func:`mass` -> ``M``: scikit-fem's ``mass`` bilinear form (``skfem.models.poisson``) with a
  per-element density, in femkit's dof order;
* :func:`condense` -> ``(A, b, x, interior)``: Dirichlet values eliminated;
* :func:`solve_direct` -> nodal ``u``: condense and a sparse direct solve.

scikit-fem is imported inside the functions only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["assemble", "condense", "skfem_quadrature", "solve_direct", "basis", "femkit_order", "mass"]


def skfem_quadrature(rule: str, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """femkit's quadrature ``rule`` as scikit-fem's ``(points, weights)`` on its reference cell.

    scikit-fem maps reference vertex ``a`` (``(0, 0)``, ``(1, 0)``, ``(0, 1)``; on tetrahedra
    also ``(0, 0, 1)``) to the cell's vertex ``a`` (``sort_t=False`` keeps femkit's order), so
    the barycentric point ``(l0, l1, ..., ld)`` is the reference point ``(l1, ..., ld)``; the
    weights (summing to 1 in femkit) are scaled by the reference cell's measure, 1/2 or 1/6.

    Parameters
    ----------
    rule : a name in :data:`femkit.fem.QUADRATURE` (``dim=2``) or
        :data:`femkit.fem.TET_QUADRATURE` (``dim=3``)
    dim : 2 (triangles) or 3 (tetrahedra)

    Returns
    -------
    points : ndarray (dim, q)
    weights : ndarray (q,)
    """
    from ...fem.quadrature import get_rule

    quad = get_rule(rule, dim=dim)
    measure = 0.5 if dim == 2 else 1.0 / 6.0
    return quad.points[:, 1:].T.copy(), quad.weights * measure


def basis(mesh, element: str = "P1", quadrature=None):
    """scikit-fem's ``Basis`` of ``element`` (``"P1"``, ``"P2"``) on femkit's ``mesh`` (its points
    and cells in femkit's order, ``sort_t=False``), with ``quadrature`` ``(points, weights)`` or
    scikit-fem's default (exact for the element's mass products)."""
    import skfem

    if mesh.dim == 3:
        m = skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy(), sort_t=False)
        elements = {"P1": skfem.ElementTetP1, "P2": skfem.ElementTetP2}
    else:
        m = skfem.MeshTri(mesh.points.T.copy(), mesh.triangles.T.copy(), sort_t=False)
        elements = {"P1": skfem.ElementTriP1, "P2": skfem.ElementTriP2}
    return skfem.Basis(m, elements[element](), quadrature=quadrature)


def femkit_order(mesh, skfem_basis, element: str = "P1") -> np.ndarray:
    """``order[i]``: scikit-fem's dof number of femkit's dof ``i``, so ``K_sk[order][:, order]``
    is femkit's matrix. Both number a cell's local dofs the same way (vertices, then edges
    (0,1), (1,2), (0,2) [, (0,3), (1,3), (2,3)]); raises ``AssertionError`` if not."""
    from ...fem.dofs import dof_map

    dofs = dof_map(mesh, element)
    theirs = np.asarray(skfem_basis.element_dofs).T                 # (m, n_local)
    order = np.full(dofs.n_dofs, -1, dtype=np.int64)
    order[dofs.cells] = theirs
    assert (order[dofs.cells] == theirs).all() and (order >= 0).all(), "dof layouts differ"
    return order


def mass(mesh, rho: np.ndarray, element: str = "P1"):
    """The mass matrix ``int rho u v`` by scikit-fem (``skfem.models.poisson.mass`` with a
    per-element ``rho``), in femkit's dof order."""
    from skfem.models.poisson import mass as mass_form

    b = basis(mesh, element)
    M = mass_form.assemble(b) if rho is None else _weighted_mass(b, rho)
    order = femkit_order(mesh, b, element)
    return M.tocsr()[order][:, order]


def _weighted_mass(b, rho):
    import skfem

    @skfem.BilinearForm
    def weighted(u, v, w):
        return w.rho * u * v

    r = np.repeat(np.asarray(rho, dtype=np.float64)[:, None], b.X.shape[1], axis=1)
    return weighted.assemble(b, rho=r)


def assemble(mesh, kappa: np.ndarray, f, *, rule: str | None = None, element: str = "P1"):
    """``(K, F)`` of ``-div(kappa grad u) = f`` on ``mesh`` by scikit-fem (P1).

    Parameters
    ----------
    mesh : a femkit mesh: triangles (``MeshTri`` + ``ElementTriP1``) or tetrahedra
        (``MeshTet`` + ``ElementTetP1``)
    kappa : (m,) per-element coefficient
    f : source, ``f(x, y)`` (``f(x, y, z)`` on tetrahedra) on arrays
    rule : femkit's quadrature rule of the same name (:func:`skfem_quadrature`; e.g.
        ``"barycentric"``, the centroid rule, which scikit-fem's ``intorder=1`` is not on
        triangles: it picks a 3-point rule) for both forms, or ``None`` for scikit-fem's
        default rule for the element. The stiffness of P1 has constant integrands: any rule
        gives it; P2's needs degree 2.
    element : ``"P1"`` or ``"P2"``; P2 matrices come in femkit's dof order (:func:`femkit_order`)

    Returns
    -------
    K : scipy.sparse.csr_matrix (n, n)
    F : ndarray (n,)
    """
    import skfem
    from skfem.helpers import dot, grad

    quadrature = None if rule is None else skfem_quadrature(rule, mesh.dim)
    b = basis(mesh, element, quadrature)

    @skfem.BilinearForm
    def stiffness(u, v, w):
        return w.kappa * dot(grad(u), grad(v))

    @skfem.LinearForm
    def load(v, w):
        return f(*w.x) * v

    kap = np.repeat(np.asarray(kappa, dtype=np.float64)[:, None], b.X.shape[1], axis=1)
    K, F = stiffness.assemble(b, kappa=kap).tocsr(), load.assemble(b)
    if element == "P1":
        return K, F
    order = femkit_order(mesh, b, element)
    return K[order][:, order].tocsr(), F[order]


def condense(K, F, nodes: np.ndarray, values: np.ndarray):
    """``(A, b, x, interior)`` by ``skfem.condense``: ``x`` the full vector holding the
    Dirichlet ``values`` at ``nodes``, ``A``, ``b`` the system on the ``interior`` nodes."""
    import skfem

    x = np.zeros(K.shape[0])
    x[nodes] = values
    A, b, x, interior = skfem.condense(K, F, x=x, D=nodes)
    return A, b, x, interior


def solve_direct(K, F, nodes: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Nodal solution: :func:`condense` and ``skfem.solve`` (a sparse direct solve)."""
    import skfem

    return skfem.solve(*condense(K, F, nodes, values))
