"""Hand-written references of the built-in energies (tests only).

femkit's built-in materials are energy *expressions* whose kernels are generated
(femkit.solids.energy.codegen). These are the same energies written out by hand, with their
derivatives worked by hand, in plain NumPy over any number of stretch triples, so that a test can
check the generator against an independent derivation (never against itself):

* co-rotational (Mueller & Gross 2004; Sifakis & Barbic 2012):
  ``W = mu sum (s_i - 1)^2 + lam/2 (sum (s_i - 1))^2``;
* St. Venant-Kirchhoff: ``W = mu/4 sum (s_i^2 - 1)^2 + lam/8 (sum (s_i^2 - 1))^2``;
* stable neo-Hookean (Smith, de Goes & Kim 2018, eq. 13 without the constant):
  ``W = mu/2 (I_C - d) - mu (J - 1) + (lam + mu)/2 (J - 1)^2``.

:func:`assembled` builds the gradient and the (projected) Hessian of a mesh from one of them by
the SVD derivative in vectorised NumPy (LAPACK's SVD and eigh, not femkit's compiled ones): the
eigenpairs of ``dP/dF`` in the principal frame (Xu, Sin, Zhu & Barbic 2015; Teran, Sifakis,
Irving & Fedkiw 2005), each element's ``vol G^T (dP/dF) G`` summed into a dense matrix.
"""

from __future__ import annotations

import numpy as np

from femkit.solids import invertible_svd

NAMES = ("corotational", "stvk", "stable_neo_hookean")


def hand(name: str, s, mu: float, lam: float):
    """``(W, dW/ds, d^2W/ds^2)`` of the built-in ``name`` at stretches ``s`` ``(..., d)``."""
    s = np.asarray(s, dtype=float)
    d = s.shape[-1]
    eye = np.eye(d)
    if name == "corotational":
        tr = (s - 1.0).sum(-1)
        W = mu * ((s - 1.0) ** 2).sum(-1) + 0.5 * lam * tr**2
        g = 2.0 * mu * (s - 1.0) + lam * tr[..., None]
        H = np.broadcast_to(lam + 2.0 * mu * eye, s.shape + (d,)).copy()
        return W, g, H
    if name == "stvk":
        e = s**2 - 1.0
        S = e.sum(-1)
        W = 0.25 * mu * (e**2).sum(-1) + 0.125 * lam * S**2
        g = mu * e * s + 0.5 * lam * S[..., None] * s
        H = lam * s[..., :, None] * s[..., None, :]
        H += eye * (mu * (3.0 * s**2 - 1.0) + 0.5 * lam * S[..., None])[..., None, :]
        return W, g, H
    if name == "stable_neo_hookean":
        lp = lam + mu
        J = s.prod(-1)
        W = 0.5 * mu * ((s**2).sum(-1) - d) - mu * (J - 1.0) + 0.5 * lp * (J - 1.0) ** 2
        a = lp * (J - 1.0) - mu                                   # dW/dJ
        # dJ/ds_i = product of the others (no division: safe at s_i = 0)
        c = np.stack([np.prod(np.delete(s, i, axis=-1), axis=-1) for i in range(d)], axis=-1)
        g = mu * s + a[..., None] * c
        H = lp * c[..., :, None] * c[..., None, :] + mu * eye
        for i in range(d):
            for j in range(d):
                if i != j:                                        # d^2J / ds_i ds_j
                    H[..., i, j] += a * np.prod(np.delete(s, [i, j], axis=-1), axis=-1)
        return W, g, H
    raise KeyError(name)


def principal_modes(U, s, V, g, Hs):
    """The ``d^2`` eigenpairs of ``dP/dF`` of each element from its SVD ``U, s, V`` and stretch
    derivatives ``g``, ``Hs``: eigenvalues ``(m, d^2)`` and unit modes ``(m, d^2, d, d)``
    (no repeated stretches: the plain quotients)."""
    d = s.shape[1]
    lams, modes = [], []
    w, E = np.linalg.eigh(Hs)
    for k in range(d):
        lams.append(w[:, k])
        modes.append(np.einsum("mai,mi,mbi->mab", U, E[:, :, k], V))
    r2 = 1.0 / np.sqrt(2.0)
    for i in range(d):
        for j in range(i + 1, d):
            lams.append((g[:, i] - g[:, j]) / (s[:, i] - s[:, j]))
            lams.append((g[:, i] + g[:, j]) / (s[:, i] + s[:, j]))
            p = np.einsum("ma,mb->mab", U[:, :, i], V[:, :, j])
            q = np.einsum("ma,mb->mab", U[:, :, j], V[:, :, i])
            modes += [r2 * (p + q), r2 * (p - q)]
    return np.stack(lams, axis=1), np.stack(modes, axis=1)


def assembled(name: str, X, cells, x, mu: float, lam: float, project: bool):
    """``(energy, gradient (n*d,), Hessian (n*d, n*d) dense)`` of the hand-written ``name``
    on the mesh ``X, cells`` at positions ``x`` (module docstring)."""
    X, x = np.asarray(X, float), np.asarray(x, float)
    d = X.shape[1]
    Dm = (X[cells[:, 1:]] - X[cells[:, :1]]).transpose(0, 2, 1)
    vol = np.linalg.det(Dm) / (2.0 if d == 2 else 6.0)
    Gi = np.linalg.inv(Dm)
    G = np.concatenate([-Gi.sum(axis=1, keepdims=True), Gi], axis=1)   # (m, d+1, d)
    F = np.einsum("mna,mnb->mab", x[cells], G)
    U, s, V = invertible_svd(F)
    W, g, Hs = hand(name, s, mu, lam)
    P = np.einsum("mai,mi,mbi->mab", U, g, V)
    L, Q = principal_modes(U, s, V, g, Hs)
    if project:
        L = np.maximum(L, 0.0)
    Wk = np.einsum("mkab,mnb->mkna", Q, G).reshape(len(F), d * d, -1)  # mode k at dof (n, a)
    He = np.einsum("m,mk,mki,mkj->mij", vol, L, Wk, Wk)
    ge = vol[:, None, None] * np.einsum("mab,mnb->mna", P, G)
    n = len(X)
    dofs = (cells[:, :, None] * d + np.arange(d)).reshape(len(cells), -1)
    grad = np.bincount(dofs.ravel(), weights=ge.ravel(), minlength=n * d)
    H = np.zeros((n * d, n * d))
    np.add.at(H, (dofs[:, :, None], dofs[:, None, :]), He)
    return float((vol * W).sum()), grad, H
