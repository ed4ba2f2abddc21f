"""Linear (small-strain) elasticity as a point function of ``F``.

``psi = mu |eps|^2 + lam/2 tr(eps)^2`` with ``eps = (F + F^T)/2 - I``, ``P = 2 mu eps + lam tr(eps) I``,
``dP/dF`` constant: eigenvalue 0 on the ``d(d-1)/2`` skew (infinitesimal rotation) modes, ``2 mu``
on the symmetric off-diagonal modes and the eigenpairs of ``2 mu I + lam 1 1^T`` on the diagonal
ones. Not rotation invariant: a rigid rotation by ``theta`` has ``eps = (cos theta - 1) I`` and so
spurious energy and forces of order ``theta^2`` (measured in ``tests/solids``; docs/methods.md).
Its number in the element pass is 0 (:func:`femkit.solids.kernels.element.point`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["linear_point"]


@numba.njit(cache=True)
def linear_point(F, params, level, P, lam, Q):  # pragma: no cover - compiled
    mu, la = params[0], params[1]
    d = F.shape[0]
    tr = 0.0
    for a in range(d):
        tr += F[a, a] - 1.0
    psi = 0.5 * la * tr * tr
    for a in range(d):
        for b in range(d):
            eps = 0.5 * (F[a, b] + F[b, a]) - (1.0 if a == b else 0.0)
            psi += mu * eps * eps
            if level >= 1:
                P[a, b] = 2.0 * mu * eps + (la * tr if a == b else 0.0)
    if level < 2:
        return psi
    H = np.empty((d, d))
    for i in range(d):
        for j in range(d):
            H[i, j] = la + (2.0 * mu if i == j else 0.0)
    w, E = np.linalg.eigh(H)
    for k in range(d * d):
        for a in range(d):
            for b in range(d):
                Q[k, a, b] = 0.0
    for k in range(d):
        lam[k] = w[k]
        for i in range(d):
            Q[k, i, i] = E[i, k]
    r2 = 1.0 / math.sqrt(2.0)
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            lam[k] = 2.0 * mu
            Q[k, i, j] = r2
            Q[k, j, i] = r2
            lam[k + 1] = 0.0
            Q[k + 1, i, j] = r2
            Q[k + 1, j, i] = -r2
            k += 2
    return psi
