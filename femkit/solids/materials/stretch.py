"""The built-in energies of the principal stretches (signed, ``d`` = 2 or 3).

* co-rotational: ``W = mu sum (s_i - 1)^2 + lam/2 (sum (s_i - 1))^2``, i.e.
  ``mu |F - R|^2 + lam/2 tr(R^T F - I)^2`` (Mueller & Gross 2004; Sifakis & Barbic 2012);
* St. Venant-Kirchhoff: ``W = mu |E|^2 + lam/2 tr(E)^2``, ``E = (F^T F - I)/2``, i.e.
  ``mu/4 sum (s_i^2 - 1)^2 + lam/8 (sum (s_i^2 - 1))^2``;
* stable neo-Hookean (Smith, de Goes & Kim 2018, their eq. 13 without the constant; Kim &
  Eberle 2022, "Dynamic deformables", section 6): ``W = mu/2 (I_C - d) - mu (J - 1) +
  lam'/2 (J - 1)^2`` with ``I_C = sum s_i^2``, ``J = prod s_i`` and ``lam' = lam + mu``, which
  makes its Hessian at rest the linear-elasticity tensor with ``(mu, lam)``; finite and smooth
  through inversion (``J <= 0``).
"""

from __future__ import annotations

import numba

__all__ = ["corotational_energy", "stvk_energy", "stable_neo_hookean_energy", "stretch_energy",
           "CODES"]

#: energy number of each built-in stretch material (0 is the linear material's point function;
#: the material classes carry it as ``code``)
CODES = {"corotational": 1, "stvk": 2, "stable_neo_hookean": 3}


@numba.njit(cache=True)
def corotational_energy(s, params, grad, hess):  # pragma: no cover - compiled
    mu, lam = params[0], params[1]
    d = s.shape[0]
    tr = 0.0
    W = 0.0
    for i in range(d):
        tr += s[i] - 1.0
        W += mu * (s[i] - 1.0) ** 2
    W += 0.5 * lam * tr * tr
    for i in range(d):
        grad[i] = 2.0 * mu * (s[i] - 1.0) + lam * tr
        for j in range(d):
            hess[i, j] = lam + (2.0 * mu if i == j else 0.0)
    return W


@numba.njit(cache=True)
def stvk_energy(s, params, grad, hess):  # pragma: no cover - compiled
    mu, lam = params[0], params[1]
    d = s.shape[0]
    S = 0.0
    W = 0.0
    for i in range(d):
        e = s[i] * s[i] - 1.0
        S += e
        W += 0.25 * mu * e * e
    W += 0.125 * lam * S * S
    for i in range(d):
        e = s[i] * s[i] - 1.0
        grad[i] = mu * e * s[i] + 0.5 * lam * S * s[i]
        for j in range(d):
            hess[i, j] = lam * s[i] * s[j]
        hess[i, i] += mu * (3.0 * s[i] * s[i] - 1.0) + 0.5 * lam * S
    return W


@numba.njit(cache=True)
def stable_neo_hookean_energy(s, params, grad, hess):  # pragma: no cover - compiled
    mu, lam = params[0], params[1] + params[0]
    d = s.shape[0]
    J = 1.0
    IC = 0.0
    for i in range(d):
        J *= s[i]
        IC += s[i] * s[i]
    W = 0.5 * mu * (IC - d) - mu * (J - 1.0) + 0.5 * lam * (J - 1.0) ** 2
    a = lam * (J - 1.0) - mu                     # dW/dJ
    for i in range(d):
        ci = 1.0                                  # dJ/ds_i, the product of the others
        for k in range(d):
            if k != i:
                ci *= s[k]
        grad[i] = mu * s[i] + a * ci
        for j in range(d):
            cj = 1.0
            for k in range(d):
                if k != j:
                    cj *= s[k]
            cij = 0.0                             # d^2J / ds_i ds_j
            if i != j:
                cij = 1.0
                for k in range(d):
                    if k != i and k != j:
                        cij *= s[k]
            hess[i, j] = lam * ci * cj + a * cij + (mu if i == j else 0.0)
    return W


@numba.njit(cache=True)
def stretch_energy(code, s, params, grad, hess):  # pragma: no cover - compiled
    """The energy number ``code`` (:data:`CODES`)."""
    if code == 1:
        return corotational_energy(s, params, grad, hess)
    if code == 2:
        return stvk_energy(s, params, grad, hess)
    return stable_neo_hookean_energy(s, params, grad, hess)
