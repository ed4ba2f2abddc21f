"""Every compiled (numba) piece of the elastic solids, in one module (also used by dynamics).

numba's on-disk cache is invalidated only by the source file of the cached function itself, not
by the files of the compiled functions it calls: kernels spread over several files would keep
running stale code after an edit. So the signed SVD, the linear point function, the
SVD-derivative eigensystem and the element pass live together here (sections below), and the
generated modules that compile them with the energies (:mod:`femkit.solids.energy.codegen`) carry
this file's hash in their name; materials refer to their energy by number (``code``).

Element pass
------------
One compiled pass over the elements: energy, gradient and Hessian values.

For element ``e`` with rest volume ``vol`` and shape-function gradients ``g_n``:
``F = sum_n x_n g_n^T``, energy ``vol psi(F)``, gradient ``vol P g_n`` on vertex ``n`` and Hessian
``vol sum_k lam_k w_k w_k^T`` with ``w_k[n, a] = (Q_k g_n)_a`` from the eigenpairs of ``dP/dF``
(``lam_k`` clamped at zero when projecting). The Hessian values go straight into the CSR
``data`` of a :class:`~femkit.fem.sparsity.BlockPattern` through its node-pair slots; no
Python loop over elements, no per-element matrices kept.

Signed SVD
----------
The invertible SVD of one small matrix, compiled (Irving, Teran & Fedkiw 2004).

Energies
--------
No energy is written here. Every stretch material -- the built-ins (co-rotational, StVK,
stable neo-Hookean: :mod:`femkit.solids.materials.builtin_materials`) and the ones a user designs -- is
an expression of the principal stretches whose derivatives are generated and printed as numba
functions by :mod:`femkit.solids.energy.codegen`. The functions below that call
``stretch_energy`` (:func:`_stretch_frame`, :func:`point`, :func:`element_pass`) are templates:
the generator copies their source into the module it writes, next to the generated
``stretch_energy(code, s, params, grad, hess) -> W`` (``dW/ds`` into ``grad``,
``d^2W/ds^2`` into ``hess``), and that module's copies are the ones compiled and run; called
from here they would not compile.

Linear material
---------------
Linear (small-strain) elasticity as a point function of ``F``.

``psi = mu |eps|^2 + lam/2 tr(eps)^2`` with ``eps = (F + F^T)/2 - I``, ``P = 2 mu eps + lam tr(eps) I``,
``dP/dF`` constant: eigenvalue 0 on the ``d(d-1)/2`` skew (infinitesimal rotation) modes, ``2 mu``
on the symmetric off-diagonal modes and the eigenpairs of ``2 mu I + lam 1 1^T`` on the diagonal
ones. Not rotation invariant: a rigid rotation by ``theta`` has ``eps = (cos theta - 1) I`` and so
spurious energy and forces of order ``theta^2`` (measured in ``tests/solids``; docs/methods.md).
Its number in the element pass is 0 (:func:`point`); it shares the modes of the principal frame
with ``U = V = I``.

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

A material's energy is ``stretch_energy(code, s, params, grad, hess)`` of the generated module
(a dispatch on an integer keeps every kernel cached on disk: numba does not cache functions
taking other compiled functions as arguments); :func:`_stretch_frame` evaluates the point
quantities the element pass needs.
"""

from __future__ import annotations

import math

import numba
import numpy as np

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


@numba.njit(cache=True, inline="always")
def add_nodal_forces(out, cells, grads, e, P, scale):  # pragma: no cover - compiled
    """``out[node_n] += scale P grad(phi_n)`` for each vertex ``n`` of element ``e``: a stress-like
    ``(d, d)`` matrix ``P`` turned into nodal vectors (the transpose of
    :func:`deformation_gradient`)."""
    d = P.shape[0]
    for n in range(cells.shape[1]):
        node = cells[e, n]
        for a in range(d):
            acc = 0.0
            for b in range(d):
                acc += P[a, b] * grads[e, n, b]
            out[node, a] += scale * acc


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
                # A <- J^T A J touches rows/columns p, q only (Golub & Van Loan, sym.schur2)
                A[p, p] -= t * apq
                A[q, q] += t * apq
                A[p, q] = 0.0
                A[q, p] = 0.0
                for r in range(d):
                    if r != p and r != q:
                        arp, arq = A[r, p], A[r, q]
                        A[r, p] = c * arp - sn * arq
                        A[p, r] = A[r, p]
                        A[r, q] = sn * arp + c * arq
                        A[q, r] = A[r, q]
                for k in range(d):                       # V <- V J
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p] = c * vkp - sn * vkq
                    V[k, q] = sn * vkp + c * vkq


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


# ---------------------------------------------------------------- linear material
@numba.njit(cache=True, inline="always")
def _linear_frame(F, params, level, P, lam, work, vec, d):  # pragma: no cover - compiled
    """The linear material in the form of :func:`_stretch_frame`: ``U = V = I`` (its modes are
    those of the principal frame of the identity), ``lam``: the eigenvalues of
    ``2 mu I + lam 1 1^T`` (eigenvectors ``E``), then per pair ``2 mu`` (symmetric) and ``0``
    (skew: an infinitesimal rotation)."""
    mu, la = params[0], params[1]
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
    U, V, A, E = work[0], work[1], work[2], work[4]
    for i in range(d):
        for j in range(d):
            U[i, j] = 1.0 if i == j else 0.0
            V[i, j] = U[i, j]
            A[i, j] = la + (2.0 * mu if i == j else 0.0)
    _sym_eig(A, E, d)
    for k in range(d):
        lam[k] = A[k, k]
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            lam[k] = 2.0 * mu
            lam[k + 1] = 0.0
            k += 2
    return psi


# ---------------------------------------------------------------- SVD derivative
#: relative gap below which two stretches count as repeated (or opposite)
REPEATED_TOL = 1e-8
_R2 = 1.0 / math.sqrt(2.0)


@numba.njit(cache=True, inline="always")
def _stretch_frame(code, F, params, level, P, lam, work, vec, d):  # pragma: no cover - compiled
    """Energy ``psi`` of the stretch energy number ``code``; ``level >= 1`` also the stress ``P``,
    ``level 2`` the principal frame of ``dP/dF``: ``U = work[0]``, ``V = work[1]``, the
    eigenvectors ``E = work[4]`` of the stretch Hessian and the ``d^2`` eigenvalues ``lam`` (the
    ``d`` of ``E``, then the shear and twist of each pair ``i < j``; module docstring)."""
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
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            gap = REPEATED_TOL * (abs(s[i]) + abs(s[j]))
            dm = s[i] - s[j]
            dp = s[i] + s[j]
            lam[k] = (g[i] - g[j]) / dm if abs(dm) > gap else H[i, i] - H[i, j]
            lam[k + 1] = (g[i] + g[j]) / dp if abs(dp) > gap else H[i, i] + H[i, j]
            k += 2
    return psi


@numba.njit(cache=True, inline="always")
def _frame(code, F, params, level, P, lam, work, vec, d):  # pragma: no cover - compiled
    """:func:`_linear_frame` (``code`` 0) or :func:`_stretch_frame`."""
    if code == 0:
        return _linear_frame(F, params, level, P, lam, work, vec, d)
    return _stretch_frame(code, F, params, level, P, lam, work, vec, d)


@numba.njit(cache=True)
def frame(code, F, params, level, P, lam, work, vec):  # pragma: no cover - compiled
    """:func:`_frame` with the size a constant. A function of its own, not inlined into the
    element pass: numba types it once for both sizes and both callers, which keeps the element
    pass's compilation short (LLVM may still inline the machine code)."""
    if F.shape[0] == 3:
        return _frame(code, F, params, level, P, lam, work, vec, 3)
    return _frame(code, F, params, level, P, lam, work, vec, 2)


@numba.njit(cache=True)
def _modes(work, Q):  # pragma: no cover - compiled
    """The ``d^2`` unit modes ``Q[k]`` (``d x d``, in F-space) of a frame ``U, V, E``:
    ``U diag(E[:, k]) V^T``, then per pair ``(u_i v_j^T +- u_j v_i^T) / sqrt 2``."""
    U, V, E = work[0], work[1], work[4]
    d = U.shape[0]
    for k in range(d):
        for a in range(d):
            for b in range(d):
                acc = 0.0
                for i in range(d):
                    acc += U[a, i] * E[i, k] * V[b, i]
                Q[k, a, b] = acc
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            for a in range(d):
                for b in range(d):
                    p = U[a, i] * V[b, j]
                    q = U[a, j] * V[b, i]
                    Q[k, a, b] = _R2 * (p + q)
                    Q[k + 1, a, b] = _R2 * (p - q)
            k += 2


@numba.njit(cache=True)
def point(code, F, params, level, P, lam, Q, work, vec):  # pragma: no cover - compiled
    """Point function of material number ``code`` (0 linear, else the stretch energy ``code``).

    ``level`` 0 energy only, 1 also the stress ``P`` (``d x d``), 2 also the ``d^2`` eigenpairs of
    ``dP/dF`` (``lam``, ``Q[k]`` the unit ``d x d`` mode in F-space). Returns ``psi``.
    ``work`` ``(6, d, d)`` and ``vec`` ``(2, d)`` are scratch (no allocation per element).
    """
    psi = frame(code, F, params, level, P, lam, work, vec)
    if level >= 2:
        _modes(work, Q)
    return psi


@numba.njit(cache=True, inline="always")
def _mode_vectors(lam, work, h, nn, v, project, w, wl, d):  # pragma: no cover - compiled
    """The mode vectors of ``dP/dF``'s eigenpairs on ``nn`` nodes, ``w[n d + a, k] = (U M_k
    h_n)_a`` (``h_n = V^T g_n``: the rows of ``h``), and ``wl = v lam_k w``, for the kept modes
    (with ``project`` a negative eigenvalue's mode is left out). Returns ``(kept modes, sum of
    the negative eigenvalues' magnitudes)``. Shared by both element passes."""
    U, E = work[0], work[4]
    ng = 0.0
    na = 0                          # the modes kept (a clamped one adds nothing)
    for k in range(d):
        if lam[k] < 0.0:
            ng -= lam[k]
            if project:
                continue
        for n in range(nn):
            for a in range(d):
                acc = 0.0
                for i in range(d):
                    acc += U[a, i] * E[i, k] * h[n, i]
                w[n * d + a, na] = acc
                wl[n * d + a, na] = v * lam[k] * acc
        na += 1
    k = d
    for i in range(d):
        for j in range(i + 1, d):
            for sign in range(2):
                lk = lam[k + sign]
                if lk < 0.0:
                    ng -= lk
                    if project:
                        continue
                sg = _R2 if sign == 0 else -_R2
                for n in range(nn):
                    for a in range(d):
                        acc = _R2 * U[a, i] * h[n, j] + sg * U[a, j] * h[n, i]
                        w[n * d + a, na] = acc
                        wl[n * d + a, na] = v * lk * acc
                na += 1
            k += 2
    return na, ng


@numba.njit(cache=True, inline="always")
def _scatter_blocks(data, cells, e, node_slots, node_indptr, B, d):  # pragma: no cover - compiled
    """Add element ``e``'s Hessian ``B`` (``(nv d)^2``, node-major) into the CSR ``data`` of a
    :class:`~femkit.fem.sparsity.BlockPattern`: the ``nv^2`` blocks ``d x d``, entry ``(n, a),
    (m, c)`` at ``d^2 r0 + (slot - r0) d + a row + c`` (``r0`` the node row's start, ``row`` its
    dof width). Shared by both element passes."""
    nv = cells.shape[1]
    dd = d * d
    for n in range(nv):
        r = cells[e, n]
        r0 = node_indptr[r]
        row = d * (node_indptr[r + 1] - r0)
        for m in range(nv):
            pos = dd * r0 + (node_slots[e, n * nv + m] - r0) * d
            for a in range(d):
                for c in range(d):
                    data[pos + a * row + c] += B[n * d + a, m * d + c]


# ---------------------------------------------------------------- element pass
#: floating-point licences of the element pass: contraction to FMA, reassociation, reciprocals,
#: signless zeros -- results move by rounding only (~1e-14 relative, checked by the tests against
#: the point function and the NumPy reference); no NaN/inf assumptions (``nnan``/``ninf`` are left
#: out: a non-finite energy must still reach the caller's check)
FASTMATH = {"contract", "reassoc", "arcp", "nsz"}


@numba.njit(cache=True, fastmath=FASTMATH)
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
    """The body of :func:`element_pass` for dimension ``d`` (a constant after inlining).

    The Hessian in the principal frame, without forming the modes ``Q_k``: with
    ``h_n = V^T g_n`` the mode vector on vertex ``n`` is ``w_k[n] = Q_k g_n = U M_k h_n``, i.e.
    ``sum_i u_i E_ik h_ni`` for the ``d`` stretch modes and ``(u_i h_nj +- u_j h_ni) / sqrt 2`` for
    a pair's shear and twist. Only the vertices ``1 .. d`` are computed: ``g_0 = -sum g_n``, so the
    blocks of vertex 0 are minus the sums of the others' (rows of zero sum)."""
    nv = d + 1
    dd = d * d
    nd = d * d                          # dofs of vertices 1..d
    F = np.empty((d, d))
    P = np.zeros((d, d))
    lam = np.zeros(dd)
    work = np.zeros((6, d, d))
    vec = np.zeros((2, d))
    h = np.empty((d, d))                # h[n-1, i] = (V^T g_n)_i
    w = np.empty((nd, dd))              # w[i, k]: mode k at dof i of vertices 1..d
    wl = np.empty((nd, dd))             # vol lam[k] w[i, k]
    B = np.empty((nv * d, nv * d))      # the element Hessian
    for t in range(elems.shape[0]):
        e = elems[t]
        deformation_gradient(x, cells, grads, e, F)
        psi = frame(code, F, params, level, P, lam, work, vec)
        v = vol[e]
        energy[e] = v * psi
        if level < 1:
            continue
        if stress.shape[0] > 0:
            for a in range(d):
                for b in range(d):
                    stress[e, a, b] = P[a, b]
        add_nodal_forces(grad, cells, grads, e, P, v)
        if level < 2:
            continue
        V = work[1]
        g2 = 0.0
        for n in range(nv):
            for b in range(d):
                g2 += grads[e, n, b] * grads[e, n, b]
        for n in range(d):
            for i in range(d):
                acc = 0.0
                for b in range(d):
                    acc += V[b, i] * grads[e, n + 1, b]
                h[n, i] = acc
        na, ng = _mode_vectors(lam, work, h, d, v, project, w, wl, d)
        neg[e] = v * ng * g2
        # vertices 1..d: B[d + i, d + j] = sum_k wl[i, k] w[j, k] (symmetric)
        for i in range(nd):
            for j in range(i, nd):
                acc = 0.0
                for kk in range(na):
                    acc += wl[i, kk] * w[j, kk]
                B[d + i, d + j] = acc
                B[d + j, d + i] = acc
        # vertex 0: minus the column sums of the blocks of vertices 1..d, then the corner
        for j in range(nd):
            for a in range(d):
                acc = 0.0
                for n in range(d):
                    acc -= B[d + n * d + a, d + j]
                B[a, d + j] = acc
                B[d + j, a] = acc
        for a in range(d):
            for c in range(d):
                acc = 0.0
                for m in range(d):
                    acc -= B[a, d + m * d + c]
                B[a, c] = acc
        _scatter_blocks(data, cells, e, node_slots, node_indptr, B, d)


# ---------------------------------------------------------------- element pass at quadrature points
@numba.njit(cache=True, fastmath=FASTMATH)
def element_pass_points(code, x, cells, grads, weights, nq, elems, params, level, project,
                        node_slots, node_indptr, energy, grad, data, neg, stress):  # pragma: no cover - compiled
    """The element pass of elements whose deformation gradient varies inside them (P2: linear
    in the element), by a quadrature rule of ``nq`` points per element.

    Element ``e`` has the nodes ``cells[e]`` (any number ``nv``: 6 for P2 triangles, 10 for P2
    tetrahedra) and at its point ``q`` (row ``p = e nq + q`` of ``grads`` ``(m nq, nv, d)`` and
    ``weights`` ``(m nq,)``) the shape-function gradients ``g_n`` and the weight ``w_p``
    (quadrature weight times the rest Jacobian). Then ``F_p = sum_n x_n g_n^T``, energy
    ``sum_q w_p psi(F_p)``, gradient ``w_p P_p g_n`` and Hessian ``sum_q w_p g^T (dP/dF)_p g``, the
    latter from the eigenpairs of ``dP/dF`` at each point, every negative one clamped at 0 when
    ``project`` (so the element Hessian, a sum of PSD terms, is PSD). ``neg[e]`` sums
    ``w_p |lam_k^-| |g|_F^2`` over the points (as :func:`element_pass`), ``stress`` ``(m nq, d,
    d)`` (when non-empty) receives ``P_p``. The element's ``(nv d)^2`` Hessian is summed over its
    points, then scattered once through ``node_slots`` (a pattern of ``(m, nv)`` cells).
    """
    if x.shape[1] == 3:
        _element_pass_points(code, x, cells, grads, weights, nq, elems, params, level, project,
                             node_slots, node_indptr, energy, grad, data, neg, stress, 3)
    else:
        _element_pass_points(code, x, cells, grads, weights, nq, elems, params, level, project,
                             node_slots, node_indptr, energy, grad, data, neg, stress, 2)


@numba.njit(cache=True, inline="always")
def _element_pass_points(code, x, cells, grads, weights, nq, elems, params, level, project,
                         node_slots, node_indptr, energy, grad, data, neg, stress, d):  # pragma: no cover - compiled
    """The body of :func:`element_pass_points` for dimension ``d`` (a constant after inlining):
    the mode vectors on every node, ``w_k[n] = U M_k h_n`` with ``h_n = V^T g_n``, as in
    :func:`_element_pass` but without eliminating a vertex (the nodes are not ``d + 1``)."""
    nv = cells.shape[1]
    dd = d * d
    nd = nv * d
    F = np.empty((d, d))
    P = np.zeros((d, d))
    lam = np.zeros(dd)
    work = np.zeros((6, d, d))
    vec = np.zeros((2, d))
    h = np.empty((nv, d))
    w = np.empty((nd, dd))
    wl = np.empty((nd, dd))
    B = np.empty((nd, nd))
    for t in range(elems.shape[0]):
        e = elems[t]
        total = 0.0
        ng = 0.0
        if level >= 2:
            for i in range(nd):
                for j in range(nd):
                    B[i, j] = 0.0
        for q in range(nq):
            p = e * nq + q
            for a in range(d):
                for b in range(d):
                    acc = 0.0
                    for n in range(nv):
                        acc += x[cells[e, n], a] * grads[p, n, b]
                    F[a, b] = acc
            psi = frame(code, F, params, level, P, lam, work, vec)
            v = weights[p]
            total += v * psi
            if level < 1:
                continue
            if stress.shape[0] > 0:
                for a in range(d):
                    for b in range(d):
                        stress[p, a, b] = P[a, b]
            for n in range(nv):
                node = cells[e, n]
                for a in range(d):
                    acc = 0.0
                    for b in range(d):
                        acc += P[a, b] * grads[p, n, b]
                    grad[node, a] += v * acc
            if level < 2:
                continue
            V = work[1]
            g2 = 0.0
            for n in range(nv):
                for i in range(d):
                    acc = 0.0
                    for b in range(d):
                        acc += V[b, i] * grads[p, n, b]
                        if i == 0:
                            g2 += grads[p, n, b] * grads[p, n, b]
                    h[n, i] = acc
            na, negative = _mode_vectors(lam, work, h, nv, v, project, w, wl, d)
            ng += v * negative * g2
            for i in range(nd):
                for j in range(i, nd):
                    acc = 0.0
                    for kk in range(na):
                        acc += wl[i, kk] * w[j, kk]
                    B[i, j] += acc
        energy[e] = total
        if level < 2:
            continue
        neg[e] = ng
        for i in range(nd):
            for j in range(i + 1, nd):
                B[j, i] = B[i, j]
        _scatter_blocks(data, cells, e, node_slots, node_indptr, B, d)
