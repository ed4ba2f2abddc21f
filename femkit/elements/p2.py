"""The quadratic Lagrange element P2 on triangles and tetrahedra.

Vertex ``a``: ``phi_a = lambda_a (2 lambda_a - 1)``; edge ``(a, b)``: ``phi = 4 lambda_a lambda_b``
(dofs: the ``d + 1`` vertices, then the edges in :data:`femkit.elements.base.EDGES` order).
Straight-sided (affine) cells: curved boundaries are approximated by their chords.

>>> import numpy as np
>>> e = ElementP2(2)
>>> e.basis([1/3, 1/3, 1/3]).round(12).tolist()
[[-0.111111111111, -0.111111111111, -0.111111111111, 0.444444444444, 0.444444444444, 0.444444444444]]
>>> float(e.basis(np.array([[0.2, 0.3, 0.5]])).sum())
1.0
"""

from __future__ import annotations

import numpy as np

from .base import Element

__all__ = ["ElementP2"]


class ElementP2(Element):
    """Piecewise quadratic element: one dof per vertex and one per edge (6 on a triangle, 10 on
    a tetrahedron)."""

    name = "P2"
    degree = 2
    dofs_per_edge = 1

    def lambda_basis(self, lam: np.ndarray) -> np.ndarray:
        edges = self.local_edges
        vert = lam * (2.0 * lam - 1.0)
        edge = 4.0 * lam[:, edges[:, 0]] * lam[:, edges[:, 1]]
        return np.concatenate([vert, edge], axis=1)

    def lambda_gradients(self, lam: np.ndarray) -> np.ndarray:
        q, nv = lam.shape
        edges = self.local_edges
        out = np.zeros((q, self.n_dofs, nv))
        for a in range(nv):
            out[:, a, a] = 4.0 * lam[:, a] - 1.0
        for k, (a, b) in enumerate(edges):
            out[:, nv + k, a] = 4.0 * lam[:, b]
            out[:, nv + k, b] = 4.0 * lam[:, a]
        return out
