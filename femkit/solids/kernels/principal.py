"""Stress and the eigensystem of ``dP/dF`` of an energy of the principal stretches.

For an isotropic energy density ``W(s_1, .., s_d)`` of the signed stretches of
``F = U diag(s) V^T`` the first Piola-Kirchhoff stress is ``P = U diag(dW/ds) V^T`` and the
Hessian ``dP/dF`` is diagonal in the principal frame, in ``d^2`` eigenpairs (the SVD
derivative: ``U^T dF V = A diag(s) + d diag(s) + diag(s) B`` with skew ``A = U^T dU``,
``B = dV^T V``; Xu, Sin, Zhu & Barbic 2015; Teran, Sifakis, Irving & Fedkiw 2005):

* ``d`` modes ``U diag(e_k) V^T`` with the eigenpairs ``(w_k, e_k)`` of the stretch Hessian
  ``d^2W / ds_i ds_j``;
* per pair ``i < j`` a *scaling/shear* mode ``(u_i v_j^T + u_j v_i^T) / sqrt 2`` with eigenvalue
  ``(W_i - W_j) / (s_i - s_j)`` and a *twist* mode ``(u_i v_j^T - u_j v_i^T) / sqrt 2`` with
  ``(W_i + W_j) / (s_i + s_j)``.

The 0/0 of repeated stretches: when ``|s_i - s_j| <= tol (|s_i| + |s_j|)`` the first quotient is
replaced by its limit ``W_ii - W_ij`` (exact for any energy symmetric in its arguments), and when
``|s_i + s_j|`` is that small the second by ``W_ii + W_ij`` (the limit for an energy unchanged by
flipping the signs of two stretches -- a rotation of the frame -- such as StVK or neo-Hookean;
for the co-rotational energy, which is not, it is the value of the smooth branch and the energy
itself has a kink there). Away from these points the quotients lose ``~eps / tol`` relative
accuracy, ``1e-8`` with ``tol = 1e-8``.

Projection to positive semi-definite (Teran et al. 2005): every eigenvalue clamped at 0, which
makes the element Hessian ``vol g^T (dP/dF) g`` PSD as well.

A material supplies one compiled function ``energy(s, params, grad, hess) -> W`` (writes
``dW/ds`` into ``grad`` and ``d^2W/ds^2`` into ``hess``), listed by number in
:func:`femkit.solids.materials.stretch.stretch_energy` (a dispatch on an integer keeps every
kernel cached on disk: numba does not cache functions taking other compiled functions as
arguments); :func:`stretch_point` evaluates the point quantities the element pass needs.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..materials.stretch import stretch_energy
from .svd import signed_svd

#: relative gap below which two stretches count as repeated (or opposite)
REPEATED_TOL = 1e-8
_R2 = 1.0 / math.sqrt(2.0)


@numba.njit(cache=True)
def stretch_point(code, F, params, level, P, lam, Q):  # pragma: no cover - compiled
    """The point function of the stretch energy number ``code``
    (:func:`femkit.solids.materials.stretch.stretch_energy`).

    ``level`` 0 energy only, 1 also the stress ``P`` (``d x d``), 2 also the ``d^2`` eigenpairs of
    ``dP/dF`` (``lam``, ``Q[k]`` the unit ``d x d`` mode in F-space). Returns ``psi``.
    """
    d = F.shape[0]
    U, s, V = signed_svd(F)
    g = np.zeros(d)
    H = np.zeros((d, d))
    psi = stretch_energy(code, s, params, g, H)
    if level < 1:
        return psi
    for a in range(d):
        for b in range(d):
            acc = 0.0
            for i in range(d):
                acc += U[a, i] * g[i] * V[b, i]
            P[a, b] = acc
    if level < 2:
        return psi
    w, E = np.linalg.eigh(H)
    for k in range(d):
        lam[k] = w[k]
        for a in range(d):
            for b in range(d):
                acc = 0.0
                for i in range(d):
                    acc += U[a, i] * E[i, k] * V[b, i]
                Q[k, a, b] = acc
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            gap = REPEATED_TOL * (abs(s[i]) + abs(s[j]))
            dm = s[i] - s[j]
            dp = s[i] + s[j]
            lam[k] = (g[i] - g[j]) / dm if abs(dm) > gap else H[i, i] - H[i, j]
            lam[k + 1] = (g[i] + g[j]) / dp if abs(dp) > gap else H[i, i] + H[i, j]
            for a in range(d):
                for b in range(d):
                    p = U[a, i] * V[b, j]
                    q = U[a, j] * V[b, i]
                    Q[k, a, b] = _R2 * (p + q)
                    Q[k + 1, a, b] = _R2 * (p - q)
            k += 2
    return psi
