"""An independent intersection test of surfaces, in numpy alone (it never calls ipctk).

The validation of barrier contact: every frame a contact run writes is checked here, by a
method that shares no code with the contact model it checks. Two triangles that share no
vertex intersect when an edge of one crosses the other (Möller & Trumbore's segment-triangle
test, "Fast, minimum storage ray-triangle intersection", J. Graphics Tools 2(1), 1997, on each
of the six edges); two segments in the plane that share no vertex intersect when each one's end
points lie on opposite sides of the other (orientation tests). Candidate pairs come from a
uniform grid of the facets' bounding boxes. Coplanar touching triangles (a set of measure
zero) are not reported.
"""

from __future__ import annotations

import numpy as np

__all__ = ["intersecting_pairs", "segment_crosses_triangle"]


def _grid_pairs(lo: np.ndarray, hi: np.ndarray, cell: float) -> np.ndarray:
    """Pairs ``(i, j)``, ``i < j``, of boxes no wider than ``cell`` that share a grid cell
    (each box touches at most 2^d cells)."""
    k, d = lo.shape
    origin = lo.min(axis=0) if k else np.zeros(d)
    c0 = np.floor((lo - origin) / cell).astype(np.int64)
    c1 = np.floor((hi - origin) / cell).astype(np.int64)
    span = (c1.max(axis=0) if k else np.zeros(d, np.int64)) + 2
    owners, keys = [], []
    for offset in np.ndindex(*(2,) * d):
        c = c0 + np.array(offset)
        inside = np.all(c <= c1, axis=1)
        owners.append(np.flatnonzero(inside))
        keys.append(np.ravel_multi_index(c[inside].T, span))
    owners, keys = np.concatenate(owners), np.concatenate(keys)
    order = np.argsort(keys, kind="stable")
    owners, keys = owners[order], keys[order]
    starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])
    sizes = np.diff(np.r_[starts, len(keys)])
    pairs = [np.zeros((0, 2), np.int64)]
    for n in np.unique(sizes[sizes > 1]):   # cells of equal occupancy together
        groups = owners[starts[sizes == n][:, None] + np.arange(n)]
        i, j = np.triu_indices(n, 1)
        pairs.append(np.stack([groups[:, i].ravel(), groups[:, j].ravel()], axis=1))
    return np.concatenate(pairs)


def _candidate_pairs(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Pairs ``(i, j)``, ``i < j``, of boxes ``[lo, hi]`` that overlap: a uniform grid of twice
    the median box width for the boxes that fit in a cell, each wider box (a large obstacle
    facet) against all."""
    k, d = lo.shape
    if k < 2:
        return np.zeros((0, 2), np.int64)
    width = np.max(hi - lo, axis=1)
    cell = 2.0 * float(np.median(width)) or float(width.max()) or 1.0
    small = np.flatnonzero(width <= cell)
    pairs = [small[_grid_pairs(lo[small], hi[small], cell)]]
    for i in np.flatnonzero(width > cell):
        j = np.flatnonzero(np.all((lo <= hi[i]) & (lo[i] <= hi), axis=1))
        j = j[j != i]
        pairs.append(np.stack([np.full(len(j), i), j], axis=1))
    p = np.sort(np.concatenate(pairs), axis=1)
    if not len(p):
        return p
    key = np.unique(p[:, 0] * np.int64(k) + p[:, 1])
    p = np.stack([key // k, key % k], axis=1)
    overlap = np.all((lo[p[:, 0]] <= hi[p[:, 1]]) & (lo[p[:, 1]] <= hi[p[:, 0]]), axis=1)
    return p[overlap]


def segment_crosses_triangle(p, q, a, b, c) -> np.ndarray:
    """Whether each segment ``p q`` crosses triangle ``a b c`` (all ``(k, 3)``): Möller-Trumbore
    with the segment parameter in ``[0, 1]``; a segment in the triangle's plane counts as not
    crossing.

    >>> import numpy as np
    >>> tri = [np.array([[0., 0, 0]]), np.array([[1., 0, 0]]), np.array([[0., 1, 0]])]
    >>> segment_crosses_triangle(np.array([[.2, .2, -1]]), np.array([[.2, .2, 1]]), *tri).tolist()
    [True]
    >>> segment_crosses_triangle(np.array([[.2, .2, .1]]), np.array([[.2, .2, 1]]), *tri).tolist()
    [False]
    """
    e1, e2, dirn = b - a, c - a, q - p
    pvec = np.cross(dirn, e2)
    det = np.einsum("kd,kd->k", e1, pvec)
    ok = np.abs(det) > 1e-300
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = p - a
    u = np.einsum("kd,kd->k", s, pvec) * inv
    qvec = np.cross(s, e1)
    v = np.einsum("kd,kd->k", dirn, qvec) * inv
    t = np.einsum("kd,kd->k", e2, qvec) * inv
    return ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)


def _orient(a, b, c) -> np.ndarray:
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def intersecting_pairs(vertices, faces, allowed=None) -> np.ndarray:
    """Pairs of facets that intersect and share no vertex.

    Parameters
    ----------
    vertices : (m, d) array
    faces : (k, 3) triangles (d = 3) or (k, 2) segments (d = 2)
    allowed : callable, optional
        ``allowed(i, j) -> bool array`` for arrays of facet indices: pairs it rejects are not
        tested (static obstacles against each other, a body against itself without
        self-contact).

    Returns
    -------
    (p, 2) int array of facet index pairs, ``i < j``.

    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [.2, .2, -1], [.2, .2, 1], [.9, .9, 1]])
    >>> intersecting_pairs(V, [[0, 1, 2], [3, 4, 5]]).tolist()
    [[0, 1]]
    """
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces, dtype=np.int64)
    P = V[F]
    pairs = _candidate_pairs(P.min(axis=1), P.max(axis=1))
    if len(pairs):
        shared = (F[pairs[:, 0]][:, :, None] == F[pairs[:, 1]][:, None, :]).any(axis=(1, 2))
        pairs = pairs[~shared]
    if len(pairs) and allowed is not None:
        pairs = pairs[np.asarray(allowed(pairs[:, 0], pairs[:, 1]), dtype=bool)]
    if not len(pairs):
        return pairs
    A, B = P[pairs[:, 0]], P[pairs[:, 1]]
    if F.shape[1] == 2:
        hit = (_orient(A[:, 0], A[:, 1], B[:, 0]) * _orient(A[:, 0], A[:, 1], B[:, 1]) <= 0) & \
              (_orient(B[:, 0], B[:, 1], A[:, 0]) * _orient(B[:, 0], B[:, 1], A[:, 1]) <= 0)
        return pairs[hit]
    hit = np.zeros(len(pairs), bool)
    for T, S in ((B, A), (A, B)):
        for i, j in ((0, 1), (1, 2), (2, 0)):
            hit |= segment_crosses_triangle(S[:, i], S[:, j], T[:, 0], T[:, 1], T[:, 2])
    return pairs[hit]
