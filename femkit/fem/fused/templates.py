"""Template kernels of the fused quadrature passes, copied into every generated module.

The passes below call ``exact_point``, ``source_point`` and ``value_point`` and read the
constants ``N_GRAD`` and ``HAS_SOURCE``; here those are placeholders. A generated module (the case
layer writes one per set of expressions, see :mod:`femkit.fem.fused`) defines them for its
functions and copies in the source of every function below that reaches them
(:func:`femkit.codegen.copied_kernels`), so numba compiles each pass with the point functions
inlined: one visit of each quadrature point evaluates every function and adds it to every
integral, and no array of point values is ever formed.

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


@numba.njit(cache=True)
def exact_point(x, y, z, out):  # pragma: no cover - placeholder, defined by the generated module
    """``out[:] = u, du/dx, du/dy[, du/dz][, f]`` at ``(x, y, z)``."""
    out[0] = np.nan


@numba.njit(cache=True)
def source_point(x, y, z, out):  # pragma: no cover - placeholder
    """``out[0] = f(x, y, z)``."""
    out[0] = np.nan


@numba.njit(cache=True)
def value_point(x, y, z, out):  # pragma: no cover - placeholder
    """``out[0] = u(x, y, z)``."""
    out[0] = np.nan


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
def nodal_value(u, cells, k, bary, q):  # pragma: no cover - compiled
    """``u_h`` at the rule's point ``q`` of cell ``k``: ``sum_a lambda_a u_a`` with fused
    multiply-adds, the rounding of the BLAS product ``u[cells] @ bary.T`` (OpenBLAS)."""
    acc = u[cells[k, 0]] * bary[q, 0]
    for a in range(1, cells.shape[1]):
        acc = fma(u[cells[k, a]], bary[q, a], acc)
    return acc


@numba.njit(cache=True, inline="always")
def coordinate(points, cells, k, bary, q, d):  # pragma: no cover - compiled
    """Coordinate ``d`` of the rule's point ``q`` on cell ``k``: ``sum_a lambda_a X_a``."""
    acc = points[cells[k, 0], d] * bary[q, 0]
    for a in range(1, cells.shape[1]):
        acc += points[cells[k, a], d] * bary[q, a]
    return acc


@numba.njit(cache=True, inline="always")
def physical_point(points, cells, k, bary, q):  # pragma: no cover - compiled
    """``(x, y, z)`` of the rule's point ``q`` on cell ``k`` (``z = 0`` in 2D)."""
    z = coordinate(points, cells, k, bary, q, 2) if points.shape[1] > 2 else 0.0
    return (coordinate(points, cells, k, bary, q, 0), coordinate(points, cells, k, bary, q, 1), z)


@numba.njit(cache=True, error_model="numpy", inline="always")  # no call per cell (~5 %)
def element_sums(points, cells, k, bary, weights, u, gh, vals):  # pragma: no cover - compiled
    """``(sum_q w_q (u_h - u)^2, sum_q w_q |grad u_h - grad u|^2, sum_q w_q f^2)`` on cell
    ``k`` (unscaled by its measure); ``gh`` the cell's gradient of ``u_h``."""
    d = points.shape[1]
    l2 = 0.0
    h1 = 0.0
    fs = 0.0
    for q in range(weights.shape[0]):
        x, y, z = physical_point(points, cells, k, bary, q)
        exact_point(x, y, z, vals)
        diff = nodal_value(u, cells, k, bary, q) - vals[0]
        l2 += weights[q] * (diff * diff)
        if N_GRAD > 0:
            s = 0.0
            for c in range(d):
                g = gh[c] - vals[1 + c]
                s += g * g
            h1 += weights[q] * s
        if HAS_SOURCE:
            f = vals[1 + N_GRAD]
            fs += weights[q] * (f * f)
    return l2, h1, fs


@numba.njit(cache=True, error_model="numpy")
def triangle_pass(points, tri, bary, weights, u, l2, h1, fsq):  # pragma: no cover - compiled
    """Per triangle ``area * element_sums`` into ``l2``, ``h1``, ``fsq``, the area and the
    gradient of ``u_h`` computed on the way; returns the number of triangles of zero or
    non-finite area (then the caller reports them by the NumPy path)."""
    vals = np.empty(4)
    gh = np.empty(2)
    bad = 0
    for k in range(tri.shape[0]):
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
        gh[0] = -(u[i0] * e0y + u[i1] * e1y + u[i2] * e2y) * inv
        gh[1] = (u[i0] * e0x + u[i1] * e1x + u[i2] * e2x) * inv
        a, b, c = element_sums(points, tri, k, bary, weights, u, gh, vals)
        l2[k] = area * a
        h1[k] = area * b
        fsq[k] = area * c
    return bad


@numba.njit(cache=True, error_model="numpy")
def source_pass(points, cells, bary, weights, measure, fsq):  # pragma: no cover - compiled
    """``fsq[k] = measure[k] * sum_q w_q f^2``: the source norm alone."""
    vals = np.empty(1)
    for k in range(cells.shape[0]):
        fs = 0.0
        for q in range(weights.shape[0]):
            x, y, z = physical_point(points, cells, k, bary, q)
            source_point(x, y, z, vals)
            fs += weights[q] * (vals[0] * vals[0])
        fsq[k] = measure[k] * fs


@numba.njit(cache=True, error_model="numpy")
def source_values(points, cells, bary, out):  # pragma: no cover - compiled
    """``out[k, q] = f`` at the rule's point ``q`` of cell ``k``: the load's source values, at
    the points :meth:`~femkit.fem.quadrature.TriangleRule.physical_points` gives (same rounding),
    without its coordinate arrays."""
    vals = np.empty(1)
    for k in range(cells.shape[0]):
        for q in range(bary.shape[0]):
            x, y, z = physical_point(points, cells, k, bary, q)
            source_point(x, y, z, vals)
            out[k, q] = vals[0]


@numba.njit(cache=True, error_model="numpy")
def nodal_pass(points, u):  # pragma: no cover - compiled
    """``max_i |u_i - u(x_i)|`` (NaN as soon as one difference is NaN, as ``np.max``)."""
    vals = np.empty(1)
    d = points.shape[1]
    big = 0.0
    for i in range(points.shape[0]):
        z = points[i, 2] if d > 2 else 0.0
        value_point(points[i, 0], points[i, 1], z, vals)
        v = abs(u[i] - vals[0])
        if v != v:
            return v
        if v > big:
            big = v
    return big


@numba.njit(cache=True, error_model="numpy")
def tetrahedron_pass(points, tets, bary, weights, u, l2, h1, fsq):  # pragma: no cover - compiled
    """Per tetrahedron ``volume * element_sums`` into ``l2``, ``h1``, ``fsq``, the volume and
    the gradient of ``u_h`` computed on the way (``D grad N_a`` by the assembly's
    :func:`femkit.fem._kernels._tetrahedron`, ``D = 6 V_signed``), so no (m, 4, 3) array of
    gradients is formed (the gradients agree with the NumPy path's to round-off); returns the
    number of tetrahedra of zero or non-finite volume (then the caller reports them by the NumPy
    path).

    The sums are :func:`element_sums`' with the element's vertices and nodal values held in
    locals (read once per element, not once per point: the point function's stores into
    ``vals`` would otherwise make every point reload them), rounded the same way: coordinates
    summed vertex by vertex, ``u_h`` by fused multiply-adds."""
    vals = np.empty(5)
    g = np.empty((4, 3))
    bad = 0
    for k in range(tets.shape[0]):
        det = _tetrahedron(tets, points, k, g)
        volume = abs(det) / 6.0
        if not (volume > 0.0 and volume < np.inf):
            bad += 1
            continue
        i0, i1, i2, i3 = tets[k, 0], tets[k, 1], tets[k, 2], tets[k, 3]
        u0, u1, u2, u3 = u[i0], u[i1], u[i2], u[i3]
        g0 = u0 * (g[0, 0] / det) + u1 * (g[1, 0] / det) + u2 * (g[2, 0] / det) + u3 * (g[3, 0] / det)
        g1 = u0 * (g[0, 1] / det) + u1 * (g[1, 1] / det) + u2 * (g[2, 1] / det) + u3 * (g[3, 1] / det)
        g2 = u0 * (g[0, 2] / det) + u1 * (g[1, 2] / det) + u2 * (g[2, 2] / det) + u3 * (g[3, 2] / det)
        x0, x1, x2, x3 = points[i0, 0], points[i1, 0], points[i2, 0], points[i3, 0]
        y0, y1, y2, y3 = points[i0, 1], points[i1, 1], points[i2, 1], points[i3, 1]
        z0, z1, z2, z3 = points[i0, 2], points[i1, 2], points[i2, 2], points[i3, 2]
        sl2 = 0.0
        sh1 = 0.0
        sfs = 0.0
        for q in range(weights.shape[0]):
            b0, b1, b2, b3 = bary[q, 0], bary[q, 1], bary[q, 2], bary[q, 3]
            exact_point(x0 * b0 + x1 * b1 + x2 * b2 + x3 * b3,
                        y0 * b0 + y1 * b1 + y2 * b2 + y3 * b3,
                        z0 * b0 + z1 * b1 + z2 * b2 + z3 * b3, vals)
            diff = fma(u3, b3, fma(u2, b2, fma(u1, b1, u0 * b0))) - vals[0]
            w = weights[q]
            sl2 += w * (diff * diff)
            if N_GRAD > 0:
                d0, d1, d2 = g0 - vals[1], g1 - vals[2], g2 - vals[3]
                sh1 += w * (d0 * d0 + d1 * d1 + d2 * d2)
            if HAS_SOURCE:
                f = vals[1 + N_GRAD]
                sfs += w * (f * f)
        l2[k] = volume * sl2
        h1[k] = volume * sh1
        fsq[k] = volume * sfs
    return bad
