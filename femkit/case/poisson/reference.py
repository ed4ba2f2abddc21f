"""The scikit-fem reference of the P1 Poisson problem: the one place femkit calls scikit-fem.

``femkit check`` (:mod:`femkit.case.poisson.cross_check`) and the convergence study's reference
rows (:mod:`femkit.study.poisson`) assemble, condense and solve the same problem with
scikit-fem (Gustafsson & McBain, "scikit-fem: A Python package for finite element assembly",
JOSS 2020) through these functions, on femkit's own mesh (points and cells in femkit's order;
triangles or tetrahedra):

* :func:`assemble` -> ``(K, F)``: stiffness with a per-element ``kappa`` and the load of a
  source ``f(x, y)``, with scikit-fem's default quadrature for P1 or, with ``one_point=True``,
  the centroid rule (the same one-point rule as femkit's ``barycentric`` load);
* :func:`condense` -> ``(A, b, x, interior)``: Dirichlet values eliminated;
* :func:`solve_direct` -> nodal ``u``: condense and a sparse direct solve.

scikit-fem is imported inside the functions only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["assemble", "condense", "solve_direct"]


def assemble(mesh, kappa: np.ndarray, f, *, one_point: bool = False):
    """``(K, F)`` of ``-div(kappa grad u) = f`` on ``mesh`` by scikit-fem (P1).

    Parameters
    ----------
    mesh : a femkit mesh: triangles (``MeshTri`` + ``ElementTriP1``) or tetrahedra
        (``MeshTet`` + ``ElementTetP1``)
    kappa : (m,) per-element coefficient
    f : source, ``f(x, y)`` (``f(x, y, z)`` on tetrahedra) on arrays
    one_point : the centroid rule (weight = the reference cell's measure, 1/2 or 1/6) instead
        of scikit-fem's default rule for P1; scikit-fem's ``intorder=1`` would pick a 3-point
        rule on triangles.

    Returns
    -------
    K : scipy.sparse.csr_matrix (n, n)
    F : ndarray (n,)
    """
    import skfem
    from skfem.helpers import dot, grad

    if mesh.dim == 3:  # the centroid of the reference tetrahedron, weight its volume 1/6
        m = skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy(), sort_t=False)
        element, centroid = skfem.ElementTetP1(), (np.full((3, 1), 0.25), np.array([1 / 6]))
    else:
        m = skfem.MeshTri(mesh.points.T.copy(), mesh.triangles.T.copy(), sort_t=False)
        element, centroid = skfem.ElementTriP1(), (np.array([[1 / 3], [1 / 3]]), np.array([0.5]))
    basis = skfem.Basis(m, element, quadrature=centroid if one_point else None)

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
