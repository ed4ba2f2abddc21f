"""The scikit-fem reference of the P1 Poisson problem: the one place femkit calls scikit-fem.

``femkit check`` (:mod:`femkit.case.poisson.cross_check`) and the convergence study's reference
rows (:mod:`femkit.study.poisson_convergence.run`) assemble, condense and solve the same problem with
scikit-fem (Gustafsson & McBain, "scikit-fem: A Python package for finite element assembly",
JOSS 2020) through these functions, on femkit's own mesh (points and cells in femkit's order;
triangles or tetrahedra):

* :func:`assemble` -> ``(K, F)``: stiffness with a per-element ``kappa`` and the load of a
  source ``f(x, y)``, with scikit-fem's default quadrature for P1 or, given ``rule``, one of
  femkit's quadrature rules (:mod:`femkit.fem.quadrature`) handed to scikit-fem's ``Basis``:
  the same points and weights as femkit's load with that rule;
* :func:`condense` -> ``(A, b, x, interior)``: Dirichlet values eliminated;
* :func:`solve_direct` -> nodal ``u``: condense and a sparse direct solve.

scikit-fem is imported inside the functions only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["assemble", "condense", "skfem_quadrature", "solve_direct"]


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


def assemble(mesh, kappa: np.ndarray, f, *, rule: str | None = None):
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
        default rule for P1. The stiffness of P1 has constant integrands: any rule gives it.

    Returns
    -------
    K : scipy.sparse.csr_matrix (n, n)
    F : ndarray (n,)
    """
    import skfem
    from skfem.helpers import dot, grad

    if mesh.dim == 3:
        m = skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy(), sort_t=False)
        element = skfem.ElementTetP1()
    else:
        m = skfem.MeshTri(mesh.points.T.copy(), mesh.triangles.T.copy(), sort_t=False)
        element = skfem.ElementTriP1()
    quadrature = None if rule is None else skfem_quadrature(rule, mesh.dim)
    basis = skfem.Basis(m, element, quadrature=quadrature)

    @skfem.BilinearForm
    def stiffness(u, v, w):
        return w.kappa * dot(grad(u), grad(v))

    @skfem.LinearForm
    def load(v, w):
        return f(*w.x) * v

    kap = np.repeat(np.asarray(kappa, dtype=np.float64)[:, None], basis.X.shape[1], axis=1)
    return stiffness.assemble(basis, kappa=kap).tocsr(), load.assemble(basis)


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
