"""Compiled (numba) passes of red refinement of triangles (:func:`femkit.mesh.refine`).

Used from :data:`femkit.mesh.refine.NUMBA_THRESHOLD` triangles on; they write the arrays
the NumPy path builds with ``np.stack`` (children, midpoints), element by element, without
its (m, 3) temporaries. Compiled once and cached on disk (``cache=True``), serial.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def red_children(tri, tri_edges, n):  # pragma: no cover - compiled
    """The four children of every triangle, ``(4 m, 3)``: ``(v0, m2, m1)``, ``(m2, v1, m0)``,
    ``(m1, m0, v2)``, ``(m0, m1, m2)`` with ``mk = n + tri_edges[t, k]`` (the midpoint of the
    edge opposite vertex k); counter-clockwise when the parent is."""
    m = tri.shape[0]
    out = np.empty((4 * m, 3), np.int64)
    for t in range(m):
        v0, v1, v2 = tri[t, 0], tri[t, 1], tri[t, 2]
        m0, m1, m2 = n + tri_edges[t, 0], n + tri_edges[t, 1], n + tri_edges[t, 2]
        c = 4 * t
        out[c, 0], out[c, 1], out[c, 2] = v0, m2, m1
        out[c + 1, 0], out[c + 1, 1], out[c + 1, 2] = m2, v1, m0
        out[c + 2, 0], out[c + 2, 1], out[c + 2, 2] = m1, m0, v2
        out[c + 3, 0], out[c + 3, 1], out[c + 3, 2] = m0, m1, m2
    return out


@numba.njit(cache=True)
def with_midpoints(points, edge_nodes):  # pragma: no cover - compiled
    """``points`` followed by the midpoint of every edge (``(a + b) / 2``, as ``mean`` rounds)."""
    n, d = points.shape
    out = np.empty((n + edge_nodes.shape[0], d))
    out[:n] = points
    for e in range(edge_nodes.shape[0]):
        a, b = edge_nodes[e, 0], edge_nodes[e, 1]
        for k in range(d):
            out[n + e, k] = (points[a, k] + points[b, k]) / 2.0
    return out


def warm_up() -> None:
    """Compile (or load from the on-disk cache) both kernels."""
    tri = np.array([[0, 1, 2]], np.int64)
    red_children(tri, np.array([[0, 1, 2]], np.int64), 3)
    with_midpoints(np.zeros((3, 2)), np.array([[0, 1]], np.int64))
