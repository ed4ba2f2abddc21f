"""Fused compiled passes over the springs (numba, ``cache=True``, serial).

Each kernel reads every spring once (its two end positions, stiffness, rest length) and does
all the per-spring work of one step in that pass, scattering to the nodes directly, instead of
the several NumPy passes of the sparse-product formulation (``G x``, lengths, scaling,
``G^T``). Conventions as in :mod:`femkit.dynamics.forces.jacobian`: spring ``s = (i, j)``,
``x_ij = x_j - x_i``, ``l = |x_ij|`` floored at ``floor`` (where ``u = 0``), ``u = x_ij / l``,

* Hooke force on ``i``: ``k (l - L) u`` (``j`` gets the opposite);
* dashpot force on ``i``: ``c ((v_j - v_i) . u) u``;
* Hessian block ``H = k [(1 - a) u u^T + a I]``, ``a = 1 - L/l`` (``max(a, 0)`` with the
  per-spring eigenvalue clamp), entering ``K`` with ``+H`` on ``(i, i)``, ``(j, j)`` and ``-H``
  on ``(i, j)``, ``(j, i)``;
* Liu et al. (2013)'s local step ``d_s = L_s (x_i - x_j) / |x_i - x_j|`` and its contribution
  ``J d`` to the global right-hand side: ``+k L u`` on ``j`` and ``-k L u`` on ``i``.

The kernels are imported only when a run asks for them (numba's import and, on the first run of
a fresh checkout, the compilation: see ``docs/benchmarks.md`` for the times).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _unit(x, i, j, floor, d, u):  # pragma: no cover - compiled
    """Fill ``u`` with the unit vector of ``x_j - x_i``; return the floored length."""
    s2 = 0.0
    for c in range(d):
        w = x[j, c] - x[i, c]
        u[c] = w
        s2 += w * w
    ln = math.sqrt(s2)
    if ln < floor:
        for c in range(d):
            u[c] = 0.0
        return floor
    inv = 1.0 / ln
    for c in range(d):
        u[c] *= inv
    return ln


@numba.njit(cache=True)
def spring_forces(x, si, sj, k, rest, floor, out):  # pragma: no cover - compiled
    """Hooke forces of all springs added into ``out`` ``(n, d)`` (one pass, no unit vectors:
    ``f_i = k (l - L) / l (x_j - x_i)``). Springs shorter than ``floor`` exert nothing (their
    direction is undefined; the NumPy path sets ``u = 0`` there: the same result)."""
    d = x.shape[1]
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        if d == 3:
            w0 = x[j, 0] - x[i, 0]
            w1 = x[j, 1] - x[i, 1]
            w2 = x[j, 2] - x[i, 2]
            ln = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if ln >= floor:
                f = k[s] * (ln - rest[s]) / ln
                out[i, 0] += f * w0
                out[i, 1] += f * w1
                out[i, 2] += f * w2
                out[j, 0] -= f * w0
                out[j, 1] -= f * w1
                out[j, 2] -= f * w2
        else:
            w0 = x[j, 0] - x[i, 0]
            w1 = x[j, 1] - x[i, 1]
            ln = math.sqrt(w0 * w0 + w1 * w1)
            if ln >= floor:
                f = k[s] * (ln - rest[s]) / ln
                out[i, 0] += f * w0
                out[i, 1] += f * w1
                out[j, 0] -= f * w0
                out[j, 1] -= f * w1


@numba.njit(cache=True, nogil=True)
def local_global_rhs(xf, x, si, sj, fi, fj, kr, floor, scale, const, out):  # pragma: no cover - compiled
    """Fast mass-spring local step and its right-hand side in one pass: ``out = const + scale J d``
    with, for every spring, the projection ``d_s = L_s (x_i - x_j) / |x_i - x_j|`` (``kr = k L``);
    ``J d`` puts ``+k L u`` on ``j`` and ``-k L u`` on ``i``. ``out`` and ``const`` are
    ``(n_free, d)``; ``fi[s]`` / ``fj[s]`` are the free-row numbers of spring ``s``'s ends (``-1``
    for a pinned end, computed once per run): an end's position is read from ``xf`` (the free
    nodes' current iterate) when free and from ``x`` (the pinned positions, rows ``si`` / ``sj``)
    otherwise, so the iterate is never scattered into a full array and no node-to-row lookup
    is repeated per sweep."""
    d = xf.shape[1]
    for r in range(out.shape[0]):
        for c in range(d):
            out[r, c] = const[r, c]
    if d == 3:  # written out: 3x faster than the generic loop below
        for s in range(si.shape[0]):
            a = fi[s]
            b = fj[s]
            if a >= 0:
                a0, a1, a2 = xf[a, 0], xf[a, 1], xf[a, 2]
            else:
                i = si[s]
                a0, a1, a2 = x[i, 0], x[i, 1], x[i, 2]
            if b >= 0:
                w0, w1, w2 = xf[b, 0] - a0, xf[b, 1] - a1, xf[b, 2] - a2
            else:
                j = sj[s]
                w0, w1, w2 = x[j, 0] - a0, x[j, 1] - a1, x[j, 2] - a2
            ln = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if ln < floor:
                continue
            f = scale * kr[s] / ln
            if a >= 0:
                out[a, 0] -= f * w0
                out[a, 1] -= f * w1
                out[a, 2] -= f * w2
            if b >= 0:
                out[b, 0] += f * w0
                out[b, 1] += f * w1
                out[b, 2] += f * w2
        return
    w = np.empty(d)
    for s in range(si.shape[0]):
        a = fi[s]
        b = fj[s]
        s2 = 0.0
        for c in range(d):
            pa = xf[a, c] if a >= 0 else x[si[s], c]
            pb = xf[b, c] if b >= 0 else x[sj[s], c]
            w[c] = pb - pa
            s2 += w[c] * w[c]
        ln = math.sqrt(s2)
        if ln < floor:
            continue
        f = scale * kr[s] / ln
        for c in range(d):
            if a >= 0:
                out[a, c] -= f * w[c]
            if b >= 0:
                out[b, c] += f * w[c]


@numba.njit(cache=True, nogil=True)
def spring_energy(x, si, sj, k, rest, floor):  # pragma: no cover - compiled
    """``sum_s 1/2 k_s (l_s - L_s)^2`` in one pass (``l`` floored at ``floor``, as the NumPy
    path floors it); without the GIL, so a writer thread runs meanwhile."""
    d = x.shape[1]
    total = 0.0
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        s2 = 0.0
        for c in range(d):
            w = x[j, c] - x[i, c]
            s2 += w * w
        ln = math.sqrt(s2)
        if ln < floor:
            ln = floor
        e = ln - rest[s]
        total += k[s] * e * e
    return 0.5 * total


@numba.njit(cache=True, nogil=True)
def spring_stretch(x, si, sj, rest, out):  # pragma: no cover - compiled
    """``out[s] = |x_j - x_i| / L_s - 1`` (a frame's ``stretch``), the same operations in the
    same order as the NumPy expression ``sqrt(einsum("sd,sd->s", dx, dx)) / rest - 1`` (equal
    bits with NumPy 2's einsum); without the GIL, so the run's thread goes on while a writer thread computes it."""
    d = x.shape[1]
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        if d == 3:  # NumPy's einsum sums a row of 3 as (w0^2 + w2^2) + w1^2
            w0 = x[j, 0] - x[i, 0]
            w1 = x[j, 1] - x[i, 1]
            w2 = x[j, 2] - x[i, 2]
            s2 = (w0 * w0 + w2 * w2) + w1 * w1
        else:
            s2 = 0.0
            for c in range(d):
                w = x[j, c] - x[i, c]
                s2 += w * w
        out[s] = math.sqrt(s2) / rest[s] - 1.0
    return out


@numba.njit(cache=True)
def hessian_values(x, v, si, sj, k, rest, damping, floor, clamp, kcoef, ccoef, slots,
                   data, force, kv):  # pragma: no cover - compiled
    """One pass over the springs for the implicit methods.

    Adds ``kcoef H_s + ccoef c_s u u^T`` of every spring into ``data`` (the values of a CSR
    matrix) at ``slots[b, s, p*d + q]`` for the four blocks ``b`` = ``(i, i)``, ``(j, j)``
    (sign +) and ``(i, j)``, ``(j, i)`` (sign -); a slot ``-1`` (a pinned row or column) is
    skipped. ``clamp``: the per-spring eigenvalue clamp ``a = max(1 - L/l, 0)``.

    In the same pass, when ``force`` has rows, the Hooke (+ dashpot, with velocities ``v``)
    forces are added into ``force`` ``(n, d)``, and when ``kv`` has rows the product ``K v``
    (``H_s`` with the same clamp) into ``kv`` ``(n, d)``.
    """
    d = x.shape[1]
    dd = d * d
    u = np.empty(d)
    blk = np.empty(dd)
    want_f = force.shape[0] > 0
    want_kv = kv.shape[0] > 0
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        ln = _unit(x, i, j, floor, d, u)
        ks = k[s]
        a = 1.0 - rest[s] / ln
        if clamp and a < 0.0:
            a = 0.0
        # H = k [(1 - a) u u^T + a I]; matrix block kcoef H + ccoef c u u^T
        bu = kcoef * ks * (1.0 - a) + ccoef * damping[s]
        ba = kcoef * ks * a
        for p in range(d):
            for q in range(d):
                blk[p * d + q] = bu * u[p] * u[q]
            blk[p * d + p] += ba
        for e in range(dd):
            val = blk[e]
            t = slots[0, s, e]
            if t >= 0:
                data[t] += val
            t = slots[1, s, e]
            if t >= 0:
                data[t] += val
            t = slots[2, s, e]
            if t >= 0:
                data[t] -= val
            t = slots[3, s, e]
            if t >= 0:
                data[t] -= val
        if want_f:
            fh = ks * (ln - rest[s])
            rel = 0.0
            if damping[s] != 0.0:
                for c in range(d):
                    rel += (v[j, c] - v[i, c]) * u[c]
                rel *= damping[s]
            for c in range(d):
                w = (fh + rel) * u[c]
                force[i, c] += w
                force[j, c] -= w
        if want_kv:
            # (K v)_i = H (v_i - v_j), (K v)_j = -(K v)_i
            ud = 0.0
            for c in range(d):
                ud += u[c] * (v[i, c] - v[j, c])
            for c in range(d):
                w = ks * (a * (v[i, c] - v[j, c]) + (1.0 - a) * ud * u[c])
                kv[i, c] += w
                kv[j, c] -= w


@numba.njit(cache=True)
def add_csr_into(indptr, indices, data, b_indptr, b_indices, b_data, scale):  # pragma: no cover
    """``data += scale * B`` where ``B`` (CSR, same shape) has its pattern inside this one
    (sorted column indices in both). Returns False (leaving ``data`` partly updated) at the
    first entry of ``B`` outside the pattern."""
    for r in range(indptr.shape[0] - 1):
        p = indptr[r]
        end = indptr[r + 1]
        for q in range(b_indptr[r], b_indptr[r + 1]):
            col = b_indices[q]
            while p < end and indices[p] < col:
                p += 1
            if p == end or indices[p] != col:
                return False
            data[p] += scale * b_data[q]
    return True
