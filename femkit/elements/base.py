"""The element abstraction: a Lagrange element on a simplex, as a small object.

An :class:`Element` describes one finite element on the reference triangle or tetrahedron
(scikit-fem's ``ElementTriP1`` is the model): its basis functions and their gradients at
barycentric points, where its degrees of freedom sit (per vertex, per edge) and the quadrature
degree its products need. It knows nothing of meshes: :mod:`femkit.fem.dofs` numbers the dofs of
a mesh (vertices first, then edges) and the assembly routines of :mod:`femkit.fem` combine an
element's reference tables with each cell's affine map.

Conventions (the stable API the Poisson, mass, solid and heat assemblies code against):

- points are **barycentric**, shape (q, d + 1), as the rules of :mod:`femkit.fem.quadrature`;
  ``lambda_0 = 1 - x_1 - ... - x_d``, ``lambda_i = x_i`` on the reference simplex;
- local dofs: the ``d + 1`` vertices first (dof ``a`` at vertex ``a``), then one per edge in
  the order of :attr:`Element.local_edges` (VTK's order, which is also scikit-fem's:
  triangle (0,1), (1,2), (0,2); tetrahedron (0,1), (1,2), (0,2), (0,3), (1,3), (2,3)), so a P2
  cell's dofs are the node list of a VTK quadratic triangle (22) or tetrahedron (24);
- :meth:`Element.basis` gives (q, n) values, :meth:`Element.lambda_gradients` (q, n, d + 1)
  derivatives with respect to the barycentric coordinates taken as independent variables, so
  that on a cell with constant barycentric gradients ``G`` (d + 1, d) the physical gradient is
  ``dphi/dlambda @ G`` (the chain rule; any polynomial extension off ``sum lambda = 1`` gives
  the same physical gradient), and :meth:`Element.gradients` (q, n, d) those with respect to
  the reference coordinates ``x_1 .. x_d``.

>>> import numpy as np
>>> from femkit.elements import get_element
>>> p2 = get_element("P2", 2)
>>> p2.n_dofs, p2.dofs_per_vertex, p2.dofs_per_edge, p2.mass_degree
(6, 1, 1, 4)
>>> p2.basis(p2.dof_points).round(12).tolist() == np.eye(6).tolist()
True
"""

from __future__ import annotations

import numpy as np

__all__ = ["Element", "EDGES"]

#: Local edges of the edge dofs, in dof order (VTK's order; scikit-fem's on the tetrahedron).
EDGES = {2: np.array([[0, 1], [1, 2], [0, 2]]),
         3: np.array([[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]])}


class Element:
    """A Lagrange element on the reference triangle (``dim=2``) or tetrahedron (``dim=3``).

    Subclasses set :attr:`name`, :attr:`degree`, :attr:`dofs_per_edge` and implement
    :meth:`lambda_basis` and :meth:`lambda_gradients`.

    Attributes
    ----------
    name : str
        The registry name (``"P1"``, ``"P2"``).
    dim : int
        2 (triangle) or 3 (tetrahedron).
    degree : int
        Polynomial degree ``p``.
    dofs_per_vertex, dofs_per_edge : int
        The dof layout: scalar Lagrange elements have one dof per vertex, P2 one per edge.
    """

    name: str = ""
    degree: int = 1
    dofs_per_vertex: int = 1
    dofs_per_edge: int = 0

    def __init__(self, dim: int):
        if dim not in (2, 3):
            raise ValueError(f"elements are defined on triangles (2) and tetrahedra (3), not dim={dim}")
        self.dim = dim

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    @property
    def cell_name(self) -> str:
        return "triangle" if self.dim == 2 else "tetrahedron"

    @property
    def local_edges(self) -> np.ndarray:
        """(k, 2) the vertex pairs of the edge dofs, in dof order (empty without edge dofs)."""
        return EDGES[self.dim] if self.dofs_per_edge else np.zeros((0, 2), dtype=np.int64)

    @property
    def n_vertices(self) -> int:
        return self.dim + 1

    @property
    def n_dofs(self) -> int:
        """Local dofs of one cell: vertices, then edges."""
        return self.n_vertices * self.dofs_per_vertex + len(EDGES[self.dim]) * self.dofs_per_edge

    @property
    def stiffness_degree(self) -> int:
        """Polynomial degree of ``grad phi_i . grad phi_j`` on an affine cell: ``2 (p - 1)``."""
        return 2 * (self.degree - 1)

    @property
    def mass_degree(self) -> int:
        """Polynomial degree of ``phi_i phi_j``: ``2 p`` (the quadrature a mass matrix needs)."""
        return 2 * self.degree

    @property
    def load_degree(self) -> int:
        """Degree of ``f phi_i`` with ``f`` of this element's degree (interpolated data): ``2 p``.
        P1 keeps its one-point load (femkit's ``barycentric`` rule) by choice of the caller."""
        return 2 * self.degree

    @property
    def dof_points(self) -> np.ndarray:
        """(n, d + 1) barycentric coordinates of the dofs: the vertices, then edge midpoints."""
        eye = np.eye(self.n_vertices)
        mids = [0.5 * (eye[a] + eye[b]) for a, b in self.local_edges]
        return np.vstack([eye, *mids]) if mids else eye

    def lambda_basis(self, lam: np.ndarray) -> np.ndarray:
        """(q, n) basis values at barycentric points ``lam`` (q, d + 1)."""
        raise NotImplementedError

    def lambda_gradients(self, lam: np.ndarray) -> np.ndarray:
        """(q, n, d + 1) derivatives of the basis with respect to the barycentric coordinates."""
        raise NotImplementedError

    def basis(self, points: np.ndarray) -> np.ndarray:
        """(q, n) basis values at barycentric ``points`` (q, d + 1) (a single point: (d + 1,))."""
        return self.lambda_basis(_points(points, self.dim))

    def gradients(self, points: np.ndarray) -> np.ndarray:
        """(q, n, d) reference gradients (with respect to ``x_1 .. x_d``) at barycentric points:
        ``dphi/dx_i = dphi/dlambda_i - dphi/dlambda_0``."""
        dl = self.lambda_gradients(_points(points, self.dim))
        return dl[:, :, 1:] - dl[:, :, :1]


def _points(points, dim: int) -> np.ndarray:
    lam = np.atleast_2d(np.asarray(points, dtype=np.float64))
    if lam.ndim != 2 or lam.shape[1] != dim + 1:
        raise ValueError(f"barycentric points of a {dim}D simplex have shape (q, {dim + 1}), "
                         f"got {np.shape(points)}")
    return lam
