"""Uniform gravity ``f_i = m_i g`` (Schlögl's lecture notes on physically based simulation)."""

from __future__ import annotations

import numpy as np

from .base import Force, as_vector, nonnegative


class Gravity(Force):
    """Gravity with acceleration ``g``.

    Parameters
    ----------
    g : float or sequence
        A vector of length ``d``, or a magnitude ``>= 0`` pointing along ``-axis``.
    axis : int
        Vertical axis for a scalar ``g``; default the last coordinate (``y`` in 2D, ``z`` in 3D).

    Energy ``-sum_i m_i g . x_i`` over the free (unpinned) components: pinned components get no
    force, so their (constant) potential is left out, and ``force = -grad(energy)`` holds entry
    by entry.

    >>> import numpy as np
    >>> from femkit.dynamics.system import MassSpringSystem
    >>> s = MassSpringSystem(np.array([[0., 0.], [0., -1.]]), 2.0, [[0, 1]], 1.0,
    ...                      pinned=[0], forces=[Gravity(10.0)])
    >>> s.force(s.x0, s.v0).tolist()
    [[0.0, 0.0], [0.0, -20.0]]
    """

    kind = "gravity"
    constant = True

    def __init__(self, g=9.81, *, axis: int = -1):
        self.g = g
        self.axis = axis

    def bind(self, system) -> None:
        super().bind(system)
        d = system.dim
        if np.ndim(self.g) == 0:
            vec = np.zeros(d)
            vec[self.axis] = -nonnegative(self.g, "gravity magnitude")
        else:
            vec = as_vector(self.g, d, "gravity vector")
        self.vector = vec
        self._weight = np.where(system.pinned_dofs, 0.0, system.mass[:, None] * vec[None, :])

    def add_force(self, x, v, t, out) -> None:
        out += self._weight

    def energy(self, x) -> float:
        return float(-np.einsum("nd,nd->", self._weight, x))

    def __repr__(self) -> str:
        return f"Gravity(g={self.g!r})"
