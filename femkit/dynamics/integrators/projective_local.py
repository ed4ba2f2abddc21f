"""The compiled local step of projective dynamics (:mod:`.projective`).

One pass over the elements: each deformation gradient ``F = U diag(s) V^T`` (the signed SVD of
:func:`femkit.elements.compiled.signed_svd`, ``det U = det V = 1``) is projected onto the
rotations, ``R = U V^T`` (as-rigid-as-possible strain), and, with a volume weight, onto the band
``J_min <= det F <= J_max`` (the nearest ``U diag(s') V^T`` with ``prod s'`` clamped into the
band: a few Gauss-Newton steps on the constraint's linearisation, Bouaziz et al. 2014, section
5); the targets go straight into the global right-hand side ``sum_e w_e D_e^T T_e``. Returns the
constraints' energy ``sum_e w_e/2 |F_e - T_e|^2`` (the local residual).

Not cached on disk (``cache=False``): numba's cache would not notice an edit of the SVD it
inlines from another file; it compiles once per process (about a second).
"""

from __future__ import annotations

import numba
import numpy as np

from ...elements.compiled import add_nodal_forces, deformation_gradient, signed_svd


@numba.njit(cache=False)
def local_step(x, cells, grads, w_rot, w_vol, jmin, jmax, out):  # pragma: no cover - compiled
    """Add ``w_rot[e] D_e^T R_e + w_vol[e] D_e^T B_e`` into ``out`` ``(n, d)`` for every element
    (``D_e x = F_e``); returns ``sum_e (w_rot |F - R|^2 + w_vol |F - B|^2) / 2``."""
    m = cells.shape[0]
    d = x.shape[1]
    F = np.empty((d, d))
    U = np.empty((d, d))
    V = np.empty((d, d))
    A = np.empty((d, d))
    T = np.empty((d, d))
    s = np.empty(d)
    sp = np.empty(d)
    gr = np.empty(d)
    local = 0.0
    for e in range(m):
        deformation_gradient(x, cells, grads, e, F)
        signed_svd(F, U, s, V, A)
        wr, wv = w_rot[e], w_vol[e]
        J = 1.0
        for i in range(d):
            J *= s[i]
        for i in range(d):
            sp[i] = s[i]
        if wv > 0.0 and (J < jmin or J > jmax):
            target = jmin if J < jmin else jmax
            for _ in range(20):
                Jc = 1.0
                for i in range(d):
                    Jc *= sp[i]
                g2 = 0.0
                lin = Jc
                for i in range(d):
                    gi = 1.0
                    for k in range(d):
                        if k != i:
                            gi *= sp[k]
                    gr[i] = gi
                    g2 += gi * gi
                    lin += gi * (s[i] - sp[i])
                if g2 == 0.0:
                    break
                lam = (target - lin) / g2
                change = 0.0
                for i in range(d):
                    new = s[i] + lam * gr[i]
                    change = max(change, abs(new - sp[i]))
                    sp[i] = new
                if change <= 1e-14 * (abs(s[0]) + 1.0):
                    break
        for a in range(d):
            for b in range(d):
                rot = 0.0
                band = 0.0
                for i in range(d):
                    rot += U[a, i] * V[b, i]
                    band += U[a, i] * sp[i] * V[b, i]
                local += 0.5 * (wr * (F[a, b] - rot) ** 2 + wv * (F[a, b] - band) ** 2)
                T[a, b] = wr * rot + wv * band
        add_nodal_forces(out, cells, grads, e, T, 1.0)
    return local
