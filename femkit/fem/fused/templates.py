"""Template kernels of the fused quadrature passes, copied into every generated module.

The passes below call ``exact_block``, ``source_block``, ``value_block`` and
``source_block_libm`` and read the constants ``N_GRAD`` and ``HAS_SOURCE``; here those are
placeholders. A generated module (the case layer writes one per set of expressions, see
:mod:`femkit.fem.fused`) defines them for its functions and copies in the source of every
function below that reaches them (:func:`femkit.codegen.copied_kernels`). Each pass walks the
cells in blocks of :data:`BLOCK`: the block's vertices are gathered (each cell's read once),
its quadrature points formed point major (point ``q`` of every cell of the block, then point
``q + 1``), every function is evaluated over them in one loop (vectorised by LLVM when the
functions are straight-line code, as the generated ones are), and the integrals of all the
block's cells are summed from that small buffer point by point, each step a loop over the cells
that LLVM vectorises too; no array of point values over the mesh is ever formed.

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

from ..cells.kernels import _tetrahedron, _triangle, _volume6

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
#: over the block in one vectorised loop (the ``*_block`` functions), then integrated.
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


@numba.njit(cache=True, nogil=True)
def block_buffers(nq, rows, nv):  # pragma: no cover - compiled
    """Coordinate buffers and a ``(rows, BLOCK * nq)`` value buffer of one block, and the
    ``(nv, 3, BLOCK)`` corner coordinates of its cells."""
    n = BLOCK * nq
    return np.empty(n), np.empty(n), np.empty(n), np.empty((rows, n)), np.empty((nv, 3, BLOCK))


@numba.njit(cache=True, inline="always")
def block_points(points, cells, k0, nt, bary, xs, ys, zs, corner):  # pragma: no cover - compiled
    """The rule's physical points on the ``nt`` cells from ``k0`` into ``xs``, ``ys``, ``zs``,
    point major: point ``q`` of cell ``k0 + t`` at ``q * nt + t`` (``z = 0`` in 2D); the cells'
    vertices are first gathered into ``corner[a, :, t]`` (read once, and left there for the
    caller), then each coordinate ``sum_a lambda_a X_a`` is summed vertex by vertex over the
    whole block (loops over the cells that LLVM vectorises)."""
    nv = cells.shape[1]
    nq = bary.shape[0]
    d = points.shape[1]
    if nv == 3 and d == 2:  # triangles: the same sums, unrolled
        for t in range(nt):
            i0, i1, i2 = cells[k0 + t, 0], cells[k0 + t, 1], cells[k0 + t, 2]
            corner[0, 0, t], corner[0, 1, t] = points[i0, 0], points[i0, 1]
            corner[1, 0, t], corner[1, 1, t] = points[i1, 0], points[i1, 1]
            corner[2, 0, t], corner[2, 1, t] = points[i2, 0], points[i2, 1]
        for q in range(nq):
            o = q * nt
            b0, b1, b2 = bary[q, 0], bary[q, 1], bary[q, 2]
            for t in range(nt):
                xs[o + t] = (corner[0, 0, t] * b0 + corner[1, 0, t] * b1) + corner[2, 0, t] * b2
                ys[o + t] = (corner[0, 1, t] * b0 + corner[1, 1, t] * b1) + corner[2, 1, t] * b2
                zs[o + t] = 0.0
        return
    for t in range(nt):
        for a in range(nv):
            i = cells[k0 + t, a]
            for c in range(d):
                corner[a, c, t] = points[i, c]
    for q in range(nq):
        o = q * nt
        b = bary[q, 0]
        for t in range(nt):
            xs[o + t] = corner[0, 0, t] * b
            ys[o + t] = corner[0, 1, t] * b
            zs[o + t] = corner[0, 2, t] * b if d > 2 else 0.0
        for a in range(1, nv):
            b = bary[q, a]
            for t in range(nt):
                xs[o + t] += corner[a, 0, t] * b
                ys[o + t] += corner[a, 1, t] * b
            if d > 2:
                for t in range(nt):
                    zs[o + t] += corner[a, 2, t] * b


@numba.njit(cache=True, error_model="numpy", inline="always")
def block_sums(cell, nv, bary, weights, vals, nt, acc, tmp):  # pragma: no cover - compiled
    """``acc[:, t]`` = ``(sum_q w_q (u_h - u)^2, sum_q w_q |grad u_h - grad u|^2, sum_q w_q f^2)``
    on the block's ``nt`` cells (unscaled by their measures), from ``cell[a, t]`` the nodal
    values of ``u_h`` (``a < nv``), ``cell[nv + j, t]`` its gradient (``j < nv - 1``) and
    ``vals[:, q * nt + t]`` what ``exact_point`` gives at point ``q`` of cell ``t``. Point by
    point, as a cell's own loop sums them: ``u_h`` by fused multiply-adds, the squares in the
    order of the gradient's components; each loop runs over the cells (vectorised). ``tmp``:
    (2, BLOCK)."""
    for t in range(nt):
        acc[0, t] = 0.0
        acc[1, t] = 0.0
        acc[2, t] = 0.0
    for q in range(weights.shape[0]):
        o = q * nt
        w = weights[q]
        if nv == 3:  # triangles: the same sums in one loop
            b0, b1, b2 = bary[q, 0], bary[q, 1], bary[q, 2]
            for t in range(nt):
                diff = fma(cell[2, t], b2, fma(cell[1, t], b1, cell[0, t] * b0)) - vals[0, o + t]
                acc[0, t] += w * (diff * diff)
                if N_GRAD > 0:
                    d0, d1 = cell[3, t] - vals[1, o + t], cell[4, t] - vals[2, o + t]
                    acc[1, t] += w * (d0 * d0 + d1 * d1)
                if HAS_SOURCE:
                    f = vals[1 + N_GRAD, o + t]
                    acc[2, t] += w * (f * f)
            continue
        b = bary[q, 0]
        for t in range(nt):
            tmp[0, t] = cell[0, t] * b
        for a in range(1, nv):
            b = bary[q, a]
            for t in range(nt):
                tmp[0, t] = fma(cell[a, t], b, tmp[0, t])
        for t in range(nt):
            diff = tmp[0, t] - vals[0, o + t]
            acc[0, t] += w * (diff * diff)
        if N_GRAD > 0:
            for t in range(nt):
                dg = cell[nv, t] - vals[1, o + t]
                tmp[1, t] = dg * dg
            for j in range(1, nv - 1):
                for t in range(nt):
                    dg = cell[nv + j, t] - vals[1 + j, o + t]
                    tmp[1, t] += dg * dg
            for t in range(nt):
                acc[1, t] += w * tmp[1, t]
        if HAS_SOURCE:
            for t in range(nt):
                f = vals[1 + N_GRAD, o + t]
                acc[2, t] += w * (f * f)


@numba.njit(cache=True, nogil=True)
def sum_buffers(nv):  # pragma: no cover - compiled
    """``cell`` ``(2 nv, BLOCK)`` (a block's ``nv`` nodal values of ``u_h``, the ``nv - 1``
    components of its gradient and the cells' measures), ``acc`` ``(3, BLOCK)`` and ``tmp``
    ``(2, BLOCK)`` of :func:`block_sums`."""
    return np.empty((2 * nv, BLOCK)), np.empty((3, BLOCK)), np.empty((2, BLOCK))


@numba.njit(cache=True, error_model="numpy", inline="always")
def store_sums(measure, acc, k0, nt, l2, h1, fsq):  # pragma: no cover - compiled
    """``measure[t] * acc[:, t]`` into ``l2``, ``h1``, ``fsq`` at ``k0 + t``; returns the number
    of cells of zero or non-finite measure (not written)."""
    bad = 0
    for t in range(nt):
        size = measure[t]
        if not (size > 0.0 and size < np.inf):
            bad += 1
            continue
        l2[k0 + t] = size * acc[0, t]
        h1[k0 + t] = size * acc[1, t]
        fsq[k0 + t] = size * acc[2, t]
    return bad


@numba.njit(cache=True, nogil=True, error_model="numpy")
def triangle_pass(points, tri, bary, weights, u, l2, h1, fsq):  # pragma: no cover - compiled
    """Per triangle ``area * block_sums`` into ``l2``, ``h1``, ``fsq``, the area and the
    gradient of ``u_h`` computed on the way; returns the number of triangles of zero or
    non-finite area (then the caller reports them by the NumPy path)."""
    nq = weights.shape[0]
    xs, ys, zs, vals, corner = block_buffers(nq, 1 + N_GRAD + HAS_SOURCE, 3)
    cell, acc, tmp = sum_buffers(3)  # u_h at the three vertices, its gradient, the area
    bad = 0
    m = tri.shape[0]
    for k0 in range(0, m, BLOCK):
        nt = min(BLOCK, m - k0)
        block_points(points, tri, k0, nt, bary, xs, ys, zs, corner)
        exact_block(xs, ys, zs, nq * nt, vals)
        for t in range(nt):
            k = k0 + t
            e0x, e0y = corner[2, 0, t] - corner[1, 0, t], corner[2, 1, t] - corner[1, 1, t]
            e1x, e1y = corner[0, 0, t] - corner[2, 0, t], corner[0, 1, t] - corner[2, 1, t]
            e2x, e2y = corner[1, 0, t] - corner[0, 0, t], corner[1, 1, t] - corner[0, 1, t]
            signed = 0.5 * (e2x * (-e1y) - e2y * (-e1x))
            inv = 1.0 / (2.0 * signed)
            u0, u1, u2 = u[tri[k, 0]], u[tri[k, 1]], u[tri[k, 2]]
            cell[0, t] = u0
            cell[1, t] = u1
            cell[2, t] = u2
            cell[3, t] = -(u0 * e0y + u1 * e1y + u2 * e2y) * inv
            cell[4, t] = (u0 * e0x + u1 * e1x + u2 * e2x) * inv
            cell[5, t] = abs(signed)
        block_sums(cell, 3, bary, weights, vals, nt, acc, tmp)
        bad += store_sums(cell[5], acc, k0, nt, l2, h1, fsq)
    return bad


@numba.njit(cache=True, error_model="numpy", inline="always")
def block_sources(points, cells, k0, bary, xs, ys, zs, vals, corner):  # pragma: no cover - compiled
    """``f`` at the rule's points of the block of cells from ``k0`` into ``vals[0]`` (point
    major, as :func:`block_points`); returns the number of cells in the block."""
    nt = min(BLOCK, cells.shape[0] - k0)
    block_points(points, cells, k0, nt, bary, xs, ys, zs, corner)
    source_block(xs, ys, zs, bary.shape[0] * nt, vals)
    return nt


@numba.njit(cache=True, nogil=True, error_model="numpy")
def source_pass(points, cells, bary, weights, measure, fsq):  # pragma: no cover - compiled
    """``fsq[k] = measure[k] * sum_q w_q f^2``: the source norm alone."""
    nq = weights.shape[0]
    xs, ys, zs, vals, corner = block_buffers(nq, 1, cells.shape[1])
    acc = np.empty(BLOCK)
    for k0 in range(0, cells.shape[0], BLOCK):
        nt = block_sources(points, cells, k0, bary, xs, ys, zs, vals, corner)
        for t in range(nt):
            acc[t] = 0.0
        for q in range(nq):
            w = weights[q]
            for t in range(nt):
                f = vals[0, q * nt + t]
                acc[t] += w * (f * f)
        for t in range(nt):
            fsq[k0 + t] = measure[k0 + t] * acc[t]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def source_values(points, cells, bary, out):  # pragma: no cover - compiled
    """``out[k, q] = f`` at the rule's point ``q`` of cell ``k``: the load's source values, at
    the points :meth:`~femkit.fem.quadrature.TriangleRule.physical_points` gives (same rounding),
    without its coordinate arrays; by the C library's functions, so the solution does not
    change with the inlined kernels."""
    nq = bary.shape[0]
    xs, ys, zs, vals, corner = block_buffers(nq, 1, cells.shape[1])
    for k0 in range(0, cells.shape[0], BLOCK):
        nt = min(BLOCK, cells.shape[0] - k0)
        block_points(points, cells, k0, nt, bary, xs, ys, zs, corner)
        source_block_libm(xs, ys, zs, nq * nt, vals)
        for t in range(nt):
            for q in range(nq):
                out[k0 + t, q] = vals[0, q * nt + t]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def barycentric_load(points, cells, bary, n):  # pragma: no cover - compiled
    """The one-point load ``F_j += |T| (f(c_T) / (d + 1))`` over every cell ``T``: ``f`` at the
    centroid ``bary`` as :func:`source_values` gives it, the measure and the sums in cell order
    as :func:`femkit.fem._kernels._load_barycentric` / ``_load_tet`` form them (the same bits),
    in one pass without the array of source values between those two. Returns ``(F, bad,
    nonfinite)``, the numbers of cells of zero or non-finite measure and of non-finite ``f``:
    when either is not 0, ``F`` is incomplete and the caller takes the two passes, which name
    them."""
    nv = cells.shape[1]
    xs, ys, zs, vals, corner = block_buffers(1, 1, nv)
    out = np.zeros(n)
    bad = 0
    nonfinite = 0
    for k0 in range(0, cells.shape[0], BLOCK):
        nt = min(BLOCK, cells.shape[0] - k0)
        block_points(points, cells, k0, nt, bary, xs, ys, zs, corner)
        source_block_libm(xs, ys, zs, nt, vals)
        for t in range(nt):
            e = k0 + t
            f = vals[0, t]
            if not abs(f) < np.inf:
                nonfinite += 1
                continue
            if nv == 3:
                i0, i1, i2, _, _, _, _, _, _, area = _triangle(cells, points, e)
                if not (area > 0.0 and area < np.inf):
                    bad += 1
                    continue
                w = area * (f / 3.0)
                out[i0] += w
                out[i1] += w
                out[i2] += w
            else:
                vol = abs(_volume6(cells, points, e)) / 6.0
                if not (vol > 0.0 and vol < np.inf):
                    bad += 1
                    continue
                w = vol * (f / 4.0)
                for a in range(4):
                    out[cells[e, a]] += w
    return out, bad, nonfinite


@numba.njit(cache=True, nogil=True, error_model="numpy")
def nodal_pass(points, u):  # pragma: no cover - compiled
    """``max_i |u_i - u(x_i)|`` (NaN as soon as one difference is NaN, as ``np.max``)."""
    d = points.shape[1]
    xs, ys, zs, vals, _ = block_buffers(1, 1, 1)
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
    """Per tetrahedron ``volume * block_sums`` into ``l2``, ``h1``, ``fsq``, the volume and
    the gradient of ``u_h`` computed on the way (``D grad N_a`` by the assembly's
    :func:`femkit.fem.cells.kernels._tetrahedron`, ``D = 6 V_signed``), so no (m, 4, 3) array of
    gradients is formed (the gradients agree with the NumPy path's to round-off); returns the
    number of tetrahedra of zero or non-finite volume (then the caller reports them by the NumPy
    path)."""
    nq = weights.shape[0]
    xs, ys, zs, vals, corner = block_buffers(nq, 1 + N_GRAD + HAS_SOURCE, 4)
    cell, acc, tmp = sum_buffers(4)  # u_h at the four vertices, its gradient, the volume
    g = np.empty((4, 3))
    bad = 0
    m = tets.shape[0]
    for k0 in range(0, m, BLOCK):
        nt = min(BLOCK, m - k0)
        block_points(points, tets, k0, nt, bary, xs, ys, zs, corner)
        exact_block(xs, ys, zs, nq * nt, vals)
        for t in range(nt):
            k = k0 + t
            det = _tetrahedron(tets, points, k, g)
            u0, u1, u2, u3 = u[tets[k, 0]], u[tets[k, 1]], u[tets[k, 2]], u[tets[k, 3]]
            cell[0, t] = u0
            cell[1, t] = u1
            cell[2, t] = u2
            cell[3, t] = u3
            for c in range(3):
                cell[4 + c, t] = (u0 * (g[0, c] / det) + u1 * (g[1, c] / det)
                                  + u2 * (g[2, c] / det) + u3 * (g[3, c] / det))
            cell[7, t] = abs(det) / 6.0
        block_sums(cell, 4, bary, weights, vals, nt, acc, tmp)
        bad += store_sums(cell[7], acc, k0, nt, l2, h1, fsq)
    return bad
