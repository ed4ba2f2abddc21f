"""Hooke springs and spring dashpots, vectorised over springs (Schlögl's lecture notes on physically based
simulation, mass-spring forces).

Spring ``s = (i, j)``: ``x_ij = x_j - x_i``, ``l = |x_ij|``, ``u = x_ij / l``.
Hooke: ``f_i = k (l - L) u = -f_j`` (the textbook ``f_i = -k (l - L) (x_i - x_j) / l`` with ``x_i - x_j = -x_ij``; a
stretched spring pulls ``i`` toward ``j``), energy ``1/2 k (l - L)^2``.
Dashpot: ``f_i = c ((v_j - v_i) . u) u = -f_j`` (damps only the rate of change of length).
The system scatters the per-spring forces with one ``np.bincount`` over precomputed
flat dof indices.
"""

from __future__ import annotations

import numpy as np

__all__ = ["spring_geometry", "geometry_from_difference", "hooke_forces", "dashpot_forces",
           "spring_energy"]


def spring_geometry(x: np.ndarray, i: np.ndarray, j: np.ndarray, floor: float = 0.0):
    """Per-spring vector, length and unit direction.

    Parameters
    ----------
    x : (n, d) positions.
    i, j : (s,) spring end indices.
    floor : lengths below this are treated as coincident (``u = 0``).

    Returns
    -------
    dx : (s, d) ``x_j - x_i``; length : (s,) ``|dx|`` floored at ``floor``; u : (s, d).

    >>> dx, l, u = spring_geometry(np.array([[0., 0.], [3., 4.]]), np.array([0]), np.array([1]))
    >>> float(l[0]), u[0].tolist()
    (5.0, [0.6, 0.8])
    """
    return geometry_from_difference(np.take(x, j, axis=0) - np.take(x, i, axis=0), floor)


def geometry_from_difference(dx: np.ndarray, floor: float = 0.0):
    """:func:`spring_geometry` from the spring vectors ``dx = x_j - x_i``, ``(s, d)``."""
    length = np.sqrt(np.einsum("sd,sd->s", dx, dx))
    if floor > 0.0:
        tiny = length < floor
        if tiny.any():
            inv = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, length))
            return dx, np.maximum(length, floor), dx * inv[:, None]
    return dx, length, dx / length[:, None]


def hooke_forces(length: np.ndarray, u: np.ndarray, k, rest) -> np.ndarray:
    """Per-spring force on end ``i``: ``k (l - L) u`` (end ``j`` gets the opposite)."""
    return (k * (length - rest))[:, None] * u


def dashpot_forces(vi: np.ndarray, vj: np.ndarray, u: np.ndarray, c) -> np.ndarray:
    """Per-spring dashpot force on end ``i``: ``c ((v_j - v_i) . u) u``."""
    rel = np.einsum("sd,sd->s", vj - vi, u)
    return (c * rel)[:, None] * u


def spring_energy(length: np.ndarray, k, rest) -> float:
    """``sum 1/2 k (l - L)^2``."""
    return float(0.5 * np.sum(k * (length - rest) ** 2))
