"""Small tetrahedral bodies for the contact tests (a Kuhn-subdivided cube: 6 tets per cell)."""

import numpy as np


def cube(n: int = 1, size: float = 1.0, origin=(0.0, 0.0, 0.0)):
    """Points and positively oriented tetrahedra of an ``n^3``-cell cube of edge ``size``."""
    g = np.linspace(0.0, size, n + 1)
    P = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3) + np.asarray(origin)

    def idx(i, j, k):
        return (i * (n + 1) + j) * (n + 1) + k

    tets = []
    for i in range(n):
        for j in range(n):
            for k in range(n):
                c = [idx(i + a, j + b, k + e) for a in (0, 1) for b in (0, 1) for e in (0, 1)]
                for p, q in ([1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]):
                    tets.append([c[0], c[p], c[q], c[7]])
    T = np.array(tets)
    a, b, c, d = (P[T[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    T[neg] = T[neg][:, [0, 2, 1, 3]]
    return P, T


def merged(*bodies):
    """One point set and cell list of several ``(P, T)`` bodies, and each body's node range."""
    P, T, ranges, off = [], [], [], 0
    for p, t in bodies:
        P.append(p)
        T.append(t + off)
        ranges.append(slice(off, off + len(p)))
        off += len(p)
    return np.concatenate(P), np.concatenate(T), ranges
