"""Every compiled (numba) piece of the elastic solids, in one module.

numba's on-disk cache is invalidated only by the source file of the cached function itself, not
by the files of the compiled functions it calls: kernels spread over several files would keep
running stale code after an edit. So the signed SVD, the stretch energies, the linear point
function, the SVD-derivative eigensystem and the element pass live together here (sections
below), and materials refer to their energy by number (``code``).

Element pass
------------
One compiled pass over the elements: energy, gradient and Hessian values.

For element ``e`` with rest volume ``vol`` and shape-function gradients ``g_n``:
``F = sum_n x_n g_n^T``, energy ``vol psi(F)``, gradient ``vol P g_n`` on vertex ``n`` and Hessian
``vol sum_k lam_k w_k w_k^T`` with ``w_k[n, a] = (Q_k g_n)_a`` from the eigenpairs of ``dP/dF``
(``lam_k`` clamped at zero when projecting). The Hessian values go straight into the CSR
``data`` of a :class:`~femkit.solids.pattern.BlockPattern` through its node-pair slots; no
Python loop over elements, no per-element matrices kept.

Signed SVD
----------
The invertible SVD of one small matrix, compiled (Irving, Teran & Fedkiw 2004).

Stretch energies
----------------
The built-in energies of the principal stretches (signed, ``d`` = 2 or 3).

* co-rotational: ``W = mu sum (s_i - 1)^2 + lam/2 (sum (s_i - 1))^2``, i.e.
  ``mu |F - R|^2 + lam/2 tr(R^T F - I)^2`` (Mueller & Gross 2004; Sifakis & Barbic 2012);
* St. Venant-Kirchhoff: ``W = mu |E|^2 + lam/2 tr(E)^2``, ``E = (F^T F - I)/2``, i.e.
  ``mu/4 sum (s_i^2 - 1)^2 + lam/8 (sum (s_i^2 - 1))^2``;
* stable neo-Hookean (Smith, de Goes & Kim 2018, their eq. 13 without the constant; Kim &
  Eberle 2022, "Dynamic deformables", section 6): ``W = mu/2 (I_C - d) - mu (J - 1) +
  lam'/2 (J - 1)^2`` with ``I_C = sum s_i^2``, ``J = prod s_i`` and ``lam' = lam + mu``, which
  makes its Hessian at rest the linear-elasticity tensor with ``(mu, lam)``; finite and smooth
  through inversion (``J <= 0``).

Linear material
---------------
Linear (small-strain) elasticity as a point function of ``F``.

``psi = mu |eps|^2 + lam/2 tr(eps)^2`` with ``eps = (F + F^T)/2 - I``, ``P = 2 mu eps + lam tr(eps) I``,
``dP/dF`` constant: eigenvalue 0 on the ``d(d-1)/2`` skew (infinitesimal rotation) modes, ``2 mu``
on the symmetric off-diagonal modes and the eigenpairs of ``2 mu I + lam 1 1^T`` on the diagonal
ones. Not rotation invariant: a rigid rotation by ``theta`` has ``eps = (cos theta - 1) I`` and so
spurious energy and forces of order ``theta^2`` (measured in ``tests/solids``; docs/methods.md).
Its number in the element pass is 0 (:func:`point`).

SVD derivative
--------------
Stress and the eigensystem of ``dP/dF`` of an energy of the principal stretches.

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
:func:`femkit.solids.compiled.stretch_energy` (a dispatch on an integer keeps every
kernel cached on disk: numba does not cache functions taking other compiled functions as
arguments); :func:`stretch_point` evaluates the point quantities the element pass needs.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: energy number of each built-in stretch material (0 is the linear material's point function;
#: the material classes carry it as ``code``)
CODES = {"linear": 0, "corotational": 1, "stvk": 2, "stable_neo_hookean": 3}


# ---------------------------------------------------------------- deformation gradient
@numba.njit(cache=True, inline="always")
def deformation_gradient(x, cells, grads, e, F):  # pragma: no cover - compiled
    """``F = sum_n x_n grad(phi_n)^T`` of element ``e`` into ``F`` (``grads``: the rest
    shape-function gradients, i.e. ``Ds Dm^-1``)."""
    d = F.shape[0]
    for a in range(d):
        for b in range(d):
            acc = 0.0
            for n in range(cells.shape[1]):
                acc += x[cells[e, n], a] * grads[e, n, b]
            F[a, b] = acc


# ---------------------------------------------------------------- signed SVD
@numba.njit(cache=True)
def det_small(A):  # pragma: no cover - compiled
    """Determinant of a 2x2 or 3x3 matrix."""
    if A.shape[0] == 2:
        return A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    return (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
            - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
            + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))


@numba.njit(cache=True)
def sym_eig(A, V):  # pragma: no cover - compiled
    """Eigen-decomposition of a small symmetric ``A`` by cyclic Jacobi rotations, in place:
    on return ``diag(A)`` holds the eigenvalues and the columns of ``V`` (a rotation) the
    eigenvectors (Golub & Van Loan, Matrix Computations, section 8.5). Converges quadratically;
    a 3x3 needs ~4 sweeps. No allocation. The size is passed as a constant to the inlined body,
    so its loops are unrolled for 2x2 and 3x3."""
    if A.shape[0] == 3:
        _sym_eig(A, V, 3)
    else:
        _sym_eig(A, V, 2)


@numba.njit(cache=True, inline="always")
def _sym_eig(A, V, d):  # pragma: no cover - compiled
    for a in range(d):
        for b in range(d):
            V[a, b] = 1.0 if a == b else 0.0
    for _ in range(30):
        off = 0.0
        scale = 0.0
        for p in range(d):
            scale += A[p, p] * A[p, p]
            for q in range(p + 1, d):
                off += A[p, q] * A[p, q]
        if off <= 1e-30 * scale:
            break
        for p in range(d - 1):
            for q in range(p + 1, d):
                apq = A[p, q]
                if apq == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                for k in range(d):                       # A <- A J
                    akp, akq = A[k, p], A[k, q]
                    A[k, p] = c * akp - sn * akq
                    A[k, q] = sn * akp + c * akq
                for k in range(d):                       # A <- J^T A
                    apk, aqk = A[p, k], A[q, k]
                    A[p, k] = c * apk - sn * aqk
                    A[q, k] = sn * apk + c * aqk
                for k in range(d):                       # V <- V J
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p] = c * vkp - sn * vkq
                    V[k, q] = sn * vkp + c * vkq
                A[p, q] = 0.0
                A[q, p] = 0.0


@numba.njit(cache=True)
def signed_svd(F, U, s, V, A):  # pragma: no cover - compiled
    """:func:`_signed_svd` with the size a constant (loops unrolled for 2x2 and 3x3)."""
    if F.shape[0] == 3:
        _signed_svd(F, U, s, V, A, 3)
    else:
        _signed_svd(F, U, s, V, A, 2)


@numba.njit(cache=True, inline="always")
def _signed_svd(F, U, s, V, A, d):  # pragma: no cover - compiled
    """``F = U diag(s) V^T`` with ``det U = det V = 1`` into ``U, s, V`` (``A`` scratch); ``s``
    by decreasing magnitude, the last one negative when ``det F < 0``.

    McAdams, Selle, Tamstorf, Teran & Sifakis (2011): ``V`` from the Jacobi eigenvectors of
    ``F^T F`` (sorted, made a rotation), then a Givens QR of ``F V = U R``: ``U`` is a product of
    rotations and ``diag(R)`` the signed stretches, accurate even for nearly collapsed elements
    (where ``sqrt`` of the eigenvalues of ``F^T F`` would not be). No allocation, no LAPACK."""
    for a in range(d):
        for b in range(d):
            acc = 0.0
            for k in range(d):
                acc += F[k, a] * F[k, b]
            A[a, b] = acc
    _sym_eig(A, V, d)
    for i in range(d):                                   # sort by decreasing eigenvalue
        best = i
        for j in range(i + 1, d):
            if A[j, j] > A[best, best]:
                best = j
        if best != i:
            A[i, i], A[best, best] = A[best, best], A[i, i]
            for k in range(d):
                V[k, i], V[k, best] = V[k, best], V[k, i]
    if det_small(V) < 0.0:
        for k in range(d):
            V[k, d - 1] = -V[k, d - 1]
    for a in range(d):                                   # A <- F V, then QR by Givens
        for b in range(d):
            acc = 0.0
            for k in range(d):
                acc += F[a, k] * V[k, b]
            A[a, b] = acc
    for a in range(d):                                   # U^T accumulated in U
        for b in range(d):
            U[a, b] = 1.0 if a == b else 0.0
    for col in range(d - 1):
        for row in range(col + 1, d):
            x, y = A[col, col], A[row, col]
            r = math.sqrt(x * x + y * y)
            if r == 0.0:
                continue
            c, sn = x / r, y / r
            for k in range(d):
                ai, aj = A[col, k], A[row, k]
                A[col, k] = c * ai + sn * aj
                A[row, k] = -sn * ai + c * aj
                ui, uj = U[col, k], U[row, k]
                U[col, k] = c * ui + sn * uj
                U[row, k] = -sn * ui + c * uj
    for a in range(d):
        s[a] = A[a, a]
        for b in range(a + 1, d):
            U[a, b], U[b, a] = U[b, a], U[a, b]


# ---------------------------------------------------------------- stretch energies
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


# ---------------------------------------------------------------- linear material
@numba.njit(cache=True)
def linear_point(F, params, level, P, lam, Q, work, vec):  # pragma: no cover - compiled
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
    H, E = work[4], work[5]
    for i in range(d):
        for j in range(d):
            H[i, j] = la + (2.0 * mu if i == j else 0.0)
    sym_eig(H, E)
    for k in range(d * d):
        for a in range(d):
            for b in range(d):
                Q[k, a, b] = 0.0
    for k in range(d):
        lam[k] = H[k, k]
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


# ---------------------------------------------------------------- SVD derivative
#: relative gap below which two stretches count as repeated (or opposite)
REPEATED_TOL = 1e-8
_R2 = 1.0 / math.sqrt(2.0)


@numba.njit(cache=True)
def stretch_point(code, F, params, level, P, lam, Q, work, vec):  # pragma: no cover - compiled
    """The point function of the stretch energy number ``code``
    (:func:`femkit.solids.compiled.stretch_energy`).

    ``level`` 0 energy only, 1 also the stress ``P`` (``d x d``), 2 also the ``d^2`` eigenpairs of
    ``dP/dF`` (``lam``, ``Q[k]`` the unit ``d x d`` mode in F-space). Returns ``psi``.
    ``work`` ``(6, d, d)`` and ``vec`` ``(2, d)`` are scratch (no allocation per element).
    """
    if F.shape[0] == 3:
        return _stretch_point(code, F, params, level, P, lam, Q, work, vec, 3)
    return _stretch_point(code, F, params, level, P, lam, Q, work, vec, 2)


@numba.njit(cache=True, inline="always")
def _stretch_point(code, F, params, level, P, lam, Q, work, vec, d):  # pragma: no cover - compiled
    U, V, A, H, E = work[0], work[1], work[2], work[3], work[4]
    s, g = vec[0], vec[1]
    _signed_svd(F, U, s, V, A, d)
    for i in range(d):
        g[i] = 0.0
        for j in range(d):
            H[i, j] = 0.0
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
    for i in range(d):
        for j in range(d):
            A[i, j] = H[i, j]
    _sym_eig(A, E, d)                  # eigenpairs of the stretch Hessian (H kept for the limits)
    for k in range(d):
        lam[k] = A[k, k]
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


# ---------------------------------------------------------------- element pass
@numba.njit(cache=True)
def point(code, F, params, level, P, lam, Q, work, vec):  # pragma: no cover - compiled
    """Point function of material number ``code``: 0 linear, else the stretch energy ``code``."""
    if code == 0:
        return linear_point(F, params, level, P, lam, Q, work, vec)
    return stretch_point(code, F, params, level, P, lam, Q, work, vec)


@numba.njit(cache=True)
def element_pass(code, x, cells, grads, vol, elems, params, level, project,
                 node_slots, node_indptr, energy, grad, data, neg, stress):  # pragma: no cover - compiled
    """The element pass of material number ``code`` (:func:`point`).

    Loops over ``elems``; ``level`` 0 writes ``energy[e]``, 1 also adds
    the gradient into ``grad`` ``(n, d)``, 2 also adds the Hessian values into ``data`` and the sum
    of the negative eigenvalues of ``vol dP/dF`` times ``|g|_F^2`` into ``neg[e]`` (a bound on the
    element Hessian's negative part, before projection). With a non-empty ``stress``
    ``(m, d, d)`` and ``level >= 1`` the first Piola-Kirchhoff stress of each element is written
    there too.
    """
    if x.shape[1] == 3:
        _element_pass(code, x, cells, grads, vol, elems, params, level, project, node_slots,
                      node_indptr, energy, grad, data, neg, stress, 3)
    else:
        _element_pass(code, x, cells, grads, vol, elems, params, level, project, node_slots,
                      node_indptr, energy, grad, data, neg, stress, 2)


@numba.njit(cache=True, inline="always")
def _element_pass(code, x, cells, grads, vol, elems, params, level, project, node_slots,
                  node_indptr, energy, grad, data, neg, stress, d):  # pragma: no cover - compiled
    """The body of :func:`element_pass` for dimension ``d`` (a constant after inlining)."""
    nv = d + 1
    dd = d * d
    F = np.empty((d, d))
    P = np.zeros((d, d))
    lam = np.zeros(dd)
    Q = np.zeros((dd, d, d))
    w = np.empty((nv * d, dd))          # w[i, k]: mode k at dof i (contiguous in k)
    wl = np.empty((nv * d, dd))         # lam[k] w[i, k]
    work = np.zeros((6, d, d))
    vec = np.zeros((2, d))
    base = np.empty((nv * nv, d), dtype=np.int64)
    for t in range(elems.shape[0]):
        e = elems[t]
        deformation_gradient(x, cells, grads, e, F)
        psi = point(code, F, params, level, P, lam, Q, work, vec)
        v = vol[e]
        energy[e] = v * psi
        if level < 1:
            continue
        if stress.shape[0] > 0:
            for a in range(d):
                for b in range(d):
                    stress[e, a, b] = P[a, b]
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
        na = 0                          # the modes kept (a clamped one adds nothing)
        for k in range(dd):
            if lam[k] < 0.0:
                ng -= lam[k]
                if project:
                    continue
            for n in range(nv):
                for a in range(d):
                    acc = 0.0
                    for b in range(d):
                        acc += Q[k, a, b] * grads[e, n, b]
                    w[n * d + a, na] = acc
                    wl[n * d + a, na] = v * lam[k] * acc
            na += 1
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
            for j in range(i, nv * d):
                m, c = j // d, j % d
                acc = 0.0
                for k in range(na):
                    acc += wl[i, k] * w[j, k]
                data[base[n * nv + m, a] + c] += acc
                if j != i:
                    data[base[m * nv + n, c] + a] += acc
