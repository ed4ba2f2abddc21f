"""Template kernels of the fused quadrature passes, copied into every generated module.

The passes below call ``exact_block``, ``source_block``, ``value_block`` and
``source_block_libm`` and read the constants ``N_GRAD`` and ``HAS_SOURCE``; here those are
placeholders. A generated module (the case layer writes one per set of expressions, see
:mod:`femkit.fem.fused`) defines them for its functions and copies in the source of every
function below that reaches them (:func:`femkit.codegen.copied_kernels`). Each pass walks the
cells in blocks of :data:`BLOCK`: the block's quadrature points are gathered (each cell's
vertices read once), every function is evaluated over them in one loop (vectorised by LLVM when
the functions are straight-line code, as the generated ones are), and each cell's integrals are
summed from that small buffer; no array of point values over the mesh is ever formed.

Rounding: the physical point is ``sum_a lambda_a X_a`` summed vertex by vertex, as
:meth:`femkit.fem.quadrature.TriangleRule.physical_points` does; ``u_h`` at the point is summed
with fused multiply-adds, as OpenBLAS's product ``u[cells] @ bary.T`` of the NumPy path does
(another BLAS may round it differently, by an ulp); the triangle's area and gradient are the
formulas of :func:`femkit.fem._elements.triangle_geometry` and
:func:`~femkit.fem._elements.p1_gradients`, operation for operation. Only the sum over the
points (a BLAS matrix-vector product in the NumPy path) is in another order: an element's
integral may differ in its last bit, the norms agree to round-off.
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from .._kernels import _tetrahedron

#: Components of the exact gradient ``exact_point`` gives after ``u`` (0: none).
N_GRAD = 0
#: True when ``exact_point`` gives the source ``f`` after the gradient.
HAS_SOURCE = False


@numba.njit(cache=True, nogil=True)
def exact_point(x, y, z, out):  # pragma: no cover - placeholder, defined by the generated module
    """``out[:] = u, du/dx, du/dy[, du/dz][, f]`` at ``(x, y, z)``."""
    out[0] = np.nan


@numba.njit(cache=True, nogil=True)
def source_point(x, y, z, out):  # pragma: no cover - placeholder
    """``out[0] = f(x, y, z)``."""
    out[0] = np.nan


@numba.njit(cache=True, nogil=True)
def value_point(x, y, z, out):  # pragma: no cover - placeholder
    """``out[0] = u(x, y, z)``."""
    out[0] = np.nan


@numba.njit(cache=True, nogil=True)
def exact_block(xs, ys, zs, n, out):  # pragma: no cover - placeholder
    """``out[:, p]`` = what :func:`exact_point` gives at ``(xs[p], ys[p], zs[p])``, ``p < n``."""
    out[:, :n] = np.nan


@numba.njit(cache=True, nogil=True)
def source_block(xs, ys, zs, n, out):  # pragma: no cover - placeholder
    """``out[0, p] = f(xs[p], ys[p], zs[p])``, ``p < n``."""
    out[:, :n] = np.nan


@numba.njit(cache=True, nogil=True)
def source_block_libm(xs, ys, zs, n, out):  # pragma: no cover - placeholder
    """:func:`source_block` by the C library's functions (the load: the solution's bits)."""
    out[:, :n] = np.nan


@numba.njit(cache=True, nogil=True)
def value_block(xs, ys, zs, n, out):  # pragma: no cover - placeholder
    """``out[0, p] = u(xs[p], ys[p], zs[p])``, ``p < n``."""
    out[:, :n] = np.nan


#: Cells per block: their quadrature points' coordinates are gathered, the functions evaluated
#: over the block in one vectorised loop (the ``*_block`` functions), then integrated cell by cell.
BLOCK = 32


@intrinsic
def fma(typingctx, a, b, c):  # pragma: no cover - compiled
    """``a * b + c`` rounded once (LLVM's ``llvm.fma``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        f = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(f, [context.cast(builder, v, t, types.float64)
                                for v, t in zip(args, signature.args)])

    return sig, codegen


@numba.njit(cache=True, inline="always")
def block_points(points, cells, k0, k1, bary, xs, ys, zs):  # pragma: no cover - compiled
    """The rule's physical points on cells ``k0 .. k1-1`` into ``xs``, ``ys``, ``zs`` (cell by
    cell, point by point; ``z = 0`` in 2D), each coordinate ``sum_a lambda_a X_a`` summed vertex
    by vertex, the cell's vertices read once; returns their number."""
    nv = cells.shape[1]
    nq = bary.shape[0]
    d = points.shape[1]
    corner = np.empty((3, 4))
    p = 0
    for k in range(k0, k1):
        for a in range(nv):
            i = cells[k, a]
            corner[0, a] = points[i, 0]
            corner[1, a] = points[i, 1]
            corner[2, a] = points[i, 2] if d > 2 else 0.0
        for q in range(nq):
            x = corner[0, 0] * bary[q, 0]
            y = corner[1, 0] * bary[q, 0]
            z = corner[2, 0] * bary[q, 0]
            for a in range(1, nv):
                x += corner[0, a] * bary[q, a]
                y += corner[1, a] * bary[q, a]
                z += corner[2, a] * bary[q, a]
            xs[p] = x
            ys[p] = y
            zs[p] = z if d > 2 else 0.0
            p += 1
    return p


@numba.njit(cache=True, nogil=True)
def block_buffers(nq, rows):  # pragma: no cover - compiled
    """Coordinate buffers and a ``(rows, BLOCK * nq)`` value buffer of one block."""
    n = BLOCK * nq
    return np.empty(n), np.empty(n), np.empty(n), np.empty((rows, n))


@numba.njit(cache=True, error_model="numpy", inline="always")  # no call per cell (~5 %)
def element_sums(u0, u1, u2, bary, weights, g0, g1, vals, p0):  # pragma: no cover - compiled
    """``(sum_q w_q (u_h - u)^2, sum_q w_q |grad u_h - grad u|^2, sum_q w_q f^2)`` on a
    triangle (unscaled by its area) of nodal values ``u0, u1, u2`` and gradient ``(g0, g1)`` of
    ``u_h``; ``vals[:, p0 + q]`` what ``exact_point`` gives at its point ``q``; ``u_h`` at the
    point summed with fused multiply-adds."""
    l2 = 0.0
    h1 = 0.0
    fs = 0.0
    for q in range(weights.shape[0]):
        p = p0 + q
        diff = fma(u2, bary[q, 2], fma(u1, bary[q, 1], u0 * bary[q, 0])) - vals[0, p]
        w = weights[q]
        l2 += w * (diff * diff)
        if N_GRAD > 0:
            d0, d1 = g0 - vals[1, p], g1 - vals[2, p]
            h1 += w * (d0 * d0 + d1 * d1)
        if HAS_SOURCE:
            f = vals[1 + N_GRAD, p]
            fs += w * (f * f)
    return l2, h1, fs


@numba.njit(cache=True, nogil=True, error_model="numpy")
def triangle_pass(points, tri, bary, weights, u, l2, h1, fsq):  # pragma: no cover - compiled
    """Per triangle ``area * element_sums`` into ``l2``, ``h1``, ``fsq``, the area and the
    gradient of ``u_h`` computed on the way; returns the number of triangles of zero or
    non-finite area (then the caller reports them by the NumPy path)."""
    nq = weights.shape[0]
    xs, ys, zs, vals = block_buffers(nq, 1 + N_GRAD + HAS_SOURCE)
    bad = 0
    for k0 in range(0, tri.shape[0], BLOCK):
        k1 = min(k0 + BLOCK, tri.shape[0])
        exact_block(xs, ys, zs, block_points(points, tri, k0, k1, bary, xs, ys, zs), vals)
        for k in range(k0, k1):
            i0, i1, i2 = tri[k, 0], tri[k, 1], tri[k, 2]
            e0x, e0y = points[i2, 0] - points[i1, 0], points[i2, 1] - points[i1, 1]
            e1x, e1y = points[i0, 0] - points[i2, 0], points[i0, 1] - points[i2, 1]
            e2x, e2y = points[i1, 0] - points[i0, 0], points[i1, 1] - points[i0, 1]
            signed = 0.5 * (e2x * (-e1y) - e2y * (-e1x))
            area = abs(signed)
            if not (area > 0.0 and area < np.inf):
                bad += 1
                continue
            inv = 1.0 / (2.0 * signed)
            u0, u1, u2 = u[i0], u[i1], u[i2]
            g0 = -(u0 * e0y + u1 * e1y + u2 * e2y) * inv
            g1 = (u0 * e0x + u1 * e1x + u2 * e2x) * inv
            a, b, c = element_sums(u0, u1, u2, bary, weights, g0, g1, vals, (k - k0) * nq)
            l2[k] = area * a
            h1[k] = area * b
            fsq[k] = area * c
    return bad


@numba.njit(cache=True, error_model="numpy", inline="always")
def block_sources(points, cells, k0, bary, xs, ys, zs, vals):  # pragma: no cover - compiled
    """``f`` at the rule's points of the block of cells from ``k0`` into ``vals[0]``; returns
    the end of the block."""
    k1 = min(k0 + BLOCK, cells.shape[0])
    source_block(xs, ys, zs, block_points(points, cells, k0, k1, bary, xs, ys, zs), vals)
    return k1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def source_pass(points, cells, bary, weights, measure, fsq):  # pragma: no cover - compiled
    """``fsq[k] = measure[k] * sum_q w_q f^2``: the source norm alone."""
    nq = weights.shape[0]
    xs, ys, zs, vals = block_buffers(nq, 1)
    for k0 in range(0, cells.shape[0], BLOCK):
        for k in range(k0, block_sources(points, cells, k0, bary, xs, ys, zs, vals)):
            fs = 0.0
            for q in range(nq):
                f = vals[0, (k - k0) * nq + q]
                fs += weights[q] * (f * f)
            fsq[k] = measure[k] * fs


@numba.njit(cache=True, nogil=True, error_model="numpy")
def source_values(points, cells, bary, out):  # pragma: no cover - compiled
    """``out[k, q] = f`` at the rule's point ``q`` of cell ``k``: the load's source values, at
    the points :meth:`~femkit.fem.quadrature.TriangleRule.physical_points` gives (same rounding),
    without its coordinate arrays; by the C library's functions, so the solution does not
    change with the inlined kernels."""
    nq = bary.shape[0]
    xs, ys, zs, vals = block_buffers(nq, 1)
    for k0 in range(0, cells.shape[0], BLOCK):
        k1 = min(k0 + BLOCK, cells.shape[0])
        source_block_libm(xs, ys, zs, block_points(points, cells, k0, k1, bary, xs, ys, zs), vals)
        for k in range(k0, k1):
            for q in range(nq):
                out[k, q] = vals[0, (k - k0) * nq + q]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def nodal_pass(points, u):  # pragma: no cover - compiled
    """``max_i |u_i - u(x_i)|`` (NaN as soon as one difference is NaN, as ``np.max``)."""
    d = points.shape[1]
    xs, ys, zs, vals = block_buffers(1, 1)
    big = 0.0
    for i0 in range(0, points.shape[0], BLOCK):
        n = min(BLOCK, points.shape[0] - i0)
        for p in range(n):
            xs[p] = points[i0 + p, 0]
            ys[p] = points[i0 + p, 1]
            zs[p] = points[i0 + p, 2] if d > 2 else 0.0
        value_block(xs, ys, zs, n, vals)
        for p in range(n):
            v = abs(u[i0 + p] - vals[0, p])
            if v != v:
                return v
            if v > big:
                big = v
    return big


@numba.njit(cache=True, nogil=True, error_model="numpy")
def tetrahedron_pass(points, tets, bary, weights, u, l2, h1, fsq):  # pragma: no cover - compiled
    """Per tetrahedron ``volume * element_sums`` into ``l2``, ``h1``, ``fsq``, the volume and
    the gradient of ``u_h`` computed on the way (``D grad N_a`` by the assembly's
    :func:`femkit.fem._kernels._tetrahedron`, ``D = 6 V_signed``), so no (m, 4, 3) array of
    gradients is formed (the gradients agree with the NumPy path's to round-off); returns the
    number of tetrahedra of zero or non-finite volume (then the caller reports them by the NumPy
    path).

    The sums are :func:`element_sums`' with the element's nodal values held in locals, rounded
    the same way: ``u_h`` by fused multiply-adds."""
    nq = weights.shape[0]
    xs, ys, zs, vals = block_buffers(nq, 1 + N_GRAD + HAS_SOURCE)
    g = np.empty((4, 3))
    bad = 0
    for k0 in range(0, tets.shape[0], BLOCK):
        k1 = min(k0 + BLOCK, tets.shape[0])
        exact_block(xs, ys, zs, block_points(points, tets, k0, k1, bary, xs, ys, zs), vals)
        for k in range(k0, k1):
            det = _tetrahedron(tets, points, k, g)
            volume = abs(det) / 6.0
            if not (volume > 0.0 and volume < np.inf):
                bad += 1
                continue
            u0, u1, u2, u3 = u[tets[k, 0]], u[tets[k, 1]], u[tets[k, 2]], u[tets[k, 3]]
            g0 = u0 * (g[0, 0] / det) + u1 * (g[1, 0] / det) + u2 * (g[2, 0] / det) + u3 * (g[3, 0] / det)
            g1 = u0 * (g[0, 1] / det) + u1 * (g[1, 1] / det) + u2 * (g[2, 1] / det) + u3 * (g[3, 1] / det)
            g2 = u0 * (g[0, 2] / det) + u1 * (g[1, 2] / det) + u2 * (g[2, 2] / det) + u3 * (g[3, 2] / det)
            sl2 = 0.0
            sh1 = 0.0
            sfs = 0.0
            p0 = (k - k0) * nq
            for q in range(nq):
                p = p0 + q
                b0, b1, b2, b3 = bary[q, 0], bary[q, 1], bary[q, 2], bary[q, 3]
                diff = fma(u3, b3, fma(u2, b2, fma(u1, b1, u0 * b0))) - vals[0, p]
                w = weights[q]
                sl2 += w * (diff * diff)
                if N_GRAD > 0:
                    d0, d1, d2 = g0 - vals[1, p], g1 - vals[2, p], g2 - vals[3, p]
                    sh1 += w * (d0 * d0 + d1 * d1 + d2 * d2)
                if HAS_SOURCE:
                    f = vals[1 + N_GRAD, p]
                    sfs += w * (f * f)
            l2[k] = volume * sl2
            h1[k] = volume * sh1
            fsq[k] = volume * sfs
    return bad
