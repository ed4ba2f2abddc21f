"""One compiled pass over the elements: energy, gradient and Hessian values.

For element ``e`` with rest volume ``vol`` and shape-function gradients ``g_n``:
``F = sum_n x_n g_n^T``, energy ``vol psi(F)``, gradient ``vol P g_n`` on vertex ``n`` and Hessian
``vol sum_k lam_k w_k w_k^T`` with ``w_k[n, a] = (Q_k g_n)_a`` from the eigenpairs of ``dP/dF``
(``lam_k`` clamped at zero when projecting). The Hessian values go straight into the CSR
``data`` of a :class:`~femkit.solids.pattern.BlockPattern` through its node-pair slots; no
Python loop over elements, no per-element matrices kept.
"""

from __future__ import annotations

import numba
import numpy as np

from ..materials.linear import linear_point
from .principal import stretch_point


@numba.njit(cache=True)
def point(code, F, params, level, P, lam, Q):  # pragma: no cover - compiled
    """Point function of material number ``code``: 0 linear, else the stretch energy ``code``."""
    if code == 0:
        return linear_point(F, params, level, P, lam, Q)
    return stretch_point(code, F, params, level, P, lam, Q)


@numba.njit(cache=True)
def element_pass(code, x, cells, grads, vol, elems, params, level, project,
                 node_slots, node_indptr, energy, grad, data, neg):  # pragma: no cover - compiled
    """The element pass of material number ``code`` (:func:`point`).

    Loops over ``elems``; ``level`` 0 writes ``energy[e]``, 1 also adds
    the gradient into ``grad`` ``(n, d)``, 2 also adds the Hessian values into ``data`` and the sum
    of the negative eigenvalues of ``vol dP/dF`` times ``|g|_F^2`` into ``neg[e]`` (a bound on the
    element Hessian's negative part, before projection).
    """
    d = x.shape[1]
    nv = d + 1
    dd = d * d
    F = np.empty((d, d))
    P = np.zeros((d, d))
    lam = np.zeros(dd)
    Q = np.zeros((dd, d, d))
    w = np.empty((dd, nv * d))
    base = np.empty((nv * nv, d), dtype=np.int64)
    for t in range(elems.shape[0]):
        e = elems[t]
        for a in range(d):
            for b in range(d):
                acc = 0.0
                for n in range(nv):
                    acc += x[cells[e, n], a] * grads[e, n, b]
                F[a, b] = acc
        psi = point(code, F, params, level, P, lam, Q)
        v = vol[e]
        energy[e] = v * psi
        if level < 1:
            continue
        for n in range(nv):
            node = cells[e, n]
            for a in range(d):
                acc = 0.0
                for b in range(d):
                    acc += P[a, b] * grads[e, n, b]
                grad[node, a] += v * acc
        if level < 2:
            continue
        g2 = 0.0
        for n in range(nv):
            for b in range(d):
                g2 += grads[e, n, b] * grads[e, n, b]
        ng = 0.0
        for k in range(dd):
            if lam[k] < 0.0:
                ng -= lam[k]
                if project:
                    lam[k] = 0.0
            for n in range(nv):
                for a in range(d):
                    acc = 0.0
                    for b in range(d):
                        acc += Q[k, a, b] * grads[e, n, b]
                    w[k, n * d + a] = acc
        neg[e] = v * ng * g2
        # CSR position of entry (n, a), (m, c): see BlockPattern
        for n in range(nv):
            r = cells[e, n]
            r0 = node_indptr[r]
            width = node_indptr[r + 1] - r0
            for m in range(nv):
                off = node_slots[e, n * nv + m] - r0
                for a in range(d):
                    base[n * nv + m, a] = dd * r0 + a * d * width + off * d
        for i in range(nv * d):
            n, a = i // d, i % d
            for j in range(nv * d):
                m, c = j // d, j % d
                acc = 0.0
                for k in range(dd):
                    acc += lam[k] * w[k, i] * w[k, j]
                data[base[n * nv + m, a] + c] += v * acc
