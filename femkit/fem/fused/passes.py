"""The fused passes run on a mesh: error norms, the source norm, the largest nodal error, the
load's source values and the one-point load vector itself.

Each returns None when the NumPy path must run instead: no kernels for these callables, or a
non-finite value or a degenerate cell met on the way (the NumPy path then reports it as it
always has).
"""

from __future__ import annotations

import weakref
from typing import Callable

import numpy as np

from .kernels import FusedKernels, kernels_for

#: The per-cell source norm an error pass computed on the way (weakly keyed by mesh, used once):
#: the residual estimator of the same source and rule takes it instead of a pass of its own.
_SOURCE_NORM: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _arrays(mesh, rule):
    return (np.ascontiguousarray(mesh.points, dtype=np.float64), np.ascontiguousarray(mesh.cells),
            np.ascontiguousarray(rule.points, dtype=np.float64),
            np.ascontiguousarray(rule.weights, dtype=np.float64))


def error_sums(mesh, u: np.ndarray, rule, kernels: FusedKernels):
    """Per cell ``(int (u_h - u)^2, int |grad(u_h - u)|^2 or None)`` by ``rule``, in one pass
    that also integrates ``f^2`` when the kernels fuse the source (kept for
    :func:`source_norm_sq`); None when the NumPy path must run."""
    if kernels.exact is None:
        return None
    mod = kernels.module
    points, cells, bary, weights = _arrays(mesh, rule)
    u = np.ascontiguousarray(u, dtype=np.float64)
    m = len(cells)
    l2, h1, fsq = np.empty(m), np.empty(m), np.empty(m)
    if mesh.dim == 2:
        if mod.triangle_pass(points, cells, bary, weights, u, l2, h1, fsq):
            return None                    # degenerate triangles: named by the NumPy path
    elif mod.tetrahedron_pass(points, cells, bary, weights, u, l2, h1, fsq):
        return None                        # degenerate tetrahedra: named by the NumPy path
    if not (np.isfinite(l2).all() and np.isfinite(h1).all()):
        return None
    if kernels.source is not None and mod.HAS_SOURCE and np.isfinite(fsq).all():
        try:
            _SOURCE_NORM[mesh] = (kernels.source, rule.name, fsq)
        except TypeError:                  # a mesh-like object without weak references
            pass
    return l2, (h1 if kernels.n_grad else None)


def source_norm_sq(mesh, f: Callable, measure, rule) -> np.ndarray | None:
    """``measure * sum_q w_q f^2`` per cell (``||f||_T^2`` by ``rule``): the one an error pass
    just computed for the same ``f`` and rule, else a compiled pass; None when the NumPy path
    must run. ``measure``: the cells' measures, or a function giving them (called only for
    the compiled pass)."""
    try:
        hit = _SOURCE_NORM.pop(mesh, None)
    except TypeError:
        hit = None
    if hit is not None and hit[0] is f and hit[1] == rule.name:
        return hit[2]
    kernels = kernels_for(mesh, source=f)
    if kernels is None:
        return None
    if callable(measure):
        measure = measure()
    points, cells, bary, weights = _arrays(mesh, rule)
    fsq = np.empty(len(cells))
    kernels.module.source_pass(points, cells, bary, weights,
                               np.ascontiguousarray(measure, dtype=np.float64), fsq)
    return fsq if np.isfinite(fsq).all() else None


def source_values(mesh, f: Callable, rule) -> np.ndarray | None:
    """``f`` at the physical points of ``rule`` on every cell, (m, q), by a compiled pass (the
    load vector's source values); None when the NumPy path must run."""
    kernels = kernels_for(mesh, source=f)
    if kernels is None:
        return None
    points, cells, bary, _ = _arrays(mesh, rule)
    out = np.empty((len(cells), len(bary)))
    kernels.module.source_values(points, cells, bary, out)
    return out


def barycentric_load(mesh, f: Callable, rule) -> np.ndarray | None:
    """The one-point (centroid) load vector of every cell in one compiled pass: the vector
    :func:`source_values` and :func:`femkit.fem._kernels.load_kernel` give, the same bits; None
    when those two passes must run (no kernels for ``f``, a degenerate cell or a non-finite
    source value, which they name)."""
    kernels = kernels_for(mesh, source=f)
    if kernels is None:
        return None
    points, cells, bary, _ = _arrays(mesh, rule)
    F, bad, nonfinite = kernels.module.barycentric_load(points, cells, bary, mesh.n_points)
    return F if bad == 0 and nonfinite == 0 else None


def nodal_error(mesh, u: np.ndarray, exact: Callable) -> float | None:
    """``max_i |u_i - exact(x_i)|`` by a compiled pass; None when the NumPy path must run."""
    kernels = kernels_for(mesh, exact=exact)
    if kernels is None or mesh.n_points == 0:
        return None
    big = kernels.module.nodal_pass(np.ascontiguousarray(mesh.points, dtype=np.float64),
                                    np.ascontiguousarray(u, dtype=np.float64))
    return float(big) if np.isfinite(big) else None
