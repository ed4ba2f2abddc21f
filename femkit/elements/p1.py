"""The linear Lagrange element P1 on triangles and tetrahedra: ``phi_a = lambda_a``.

>>> import numpy as np
>>> e = ElementP1(3)
>>> e.n_dofs, e.stiffness_degree
(4, 0)
>>> e.gradients([0.25, 0.25, 0.25, 0.25])[0].tolist()
[[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
"""

from __future__ import annotations

import numpy as np

from .base import Element

__all__ = ["ElementP1"]


class ElementP1(Element):
    """Piecewise linear element: one dof per vertex, basis the barycentric coordinates."""

    name = "P1"
    degree = 1
    dofs_per_edge = 0

    def lambda_basis(self, lam: np.ndarray) -> np.ndarray:
        return lam.copy()

    def lambda_gradients(self, lam: np.ndarray) -> np.ndarray:
        return np.broadcast_to(np.eye(self.n_vertices), (len(lam), self.n_vertices, self.n_vertices)).copy()
