"""P1 load vector ``F_j = int f N_j``.

The default ``barycentric`` rule is the classical one-point (centroid) rule of P1 lecture notes (e.g. Schlögl, physically based simulation; Braess, *Finite Elements*, 2007) ``F_j += |T| f(c) / 3``; named
higher-order rules (:mod:`femkit.fem.quadrature`) evaluate ``f`` at their points and weight
by the P1 basis values there.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> assemble_load(m, 6.0).tolist()
[1.0, 1.0, 1.0]
"""

from __future__ import annotations

from typing import Callable, Union

import numpy as np

from ..errors import InputError
from ._elements import check_areas, select_elements
from .coefficients import evaluate_callable
from .quadrature import get_rule
from .sparsity import NUMBA_THRESHOLD
from ..warmup_registry import register_kernels, register_threshold

register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("P1 assembly", "femkit.fem._kernels", "_load_barycentric", "_load_tet", rank=1)

Source = Union[float, Callable]


def assemble_load(mesh, f: Source, *, rule: str = "barycentric", elements=None,
                  backend: str = "auto") -> np.ndarray:
    """Assemble the load vector of the source ``f``.

    Parameters
    ----------
    mesh : Mesh
    f : float or callable f(x, y) (f(x, y, z) on tetrahedra)
    rule : str
        Quadrature rule name: ``barycentric`` (default, one point: ``F_j += |T| f(c) / (d + 1)``),
        on triangles ``gauss3``, ``gauss6``, ``gauss7``; on tetrahedra ``gauss4``, ``stroud8``,
        ``stroud27``, ``stroud64`` (:mod:`femkit.fem.quadrature`).
    elements : index array or boolean mask, optional
        Integrate over these elements only (global-size result).
    backend : {"auto", "numpy", "numba"}
        How the ``barycentric`` rule is summed: ``numpy`` (``np.bincount``), ``numba`` (one
        compiled pass computing areas and scattering, imported lazily, cached on disk), ``auto``
        (numba from :data:`~femkit.fem.sparsity.NUMBA_THRESHOLD` selected elements on).
        Callables are evaluated by numpy either way; other rules always use numpy.

    Returns
    -------
    ndarray, shape (n,)
    """
    quad = get_rule(rule, dim=mesh.dim)
    idx = select_elements(mesh, elements)
    if backend not in ("auto", "numpy", "numba"):
        raise InputError(f"unknown assembly backend {backend!r}; valid: auto, numba, numpy")
    count = mesh.n_cells if idx is None else len(idx)
    if backend == "auto":
        backend = "numba" if count >= NUMBA_THRESHOLD else "numpy"
    if backend == "numba" and quad.points.shape[0] == 1 and np.all(quad.points == quad.points[0, 0]):
        # a centroid rule (weights sum to 1): the kernel's |T| f(c) / 3 per vertex
        out = _load_numba(mesh, f, quad, idx)
        if out is not None:
            return out
    tri = mesh.cells if idx is None else mesh.cells[idx]
    area = _areas(mesh, tri)
    check_areas(area, idx, mesh.dim)
    if callable(f):
        fq = _source_values(mesh, f, quad, tri, idx)
        # local[e, a] = |T_e| sum_q w_q f(x_q) lambda_a(x_q)
        local = (fq * quad.weights) @ quad.points
        local *= area[:, None]
        return np.bincount(tri.ravel(), weights=local.ravel(), minlength=mesh.n_points)
    k = mesh.dim + 1
    w = area * (_scalar(f) / float(k))  # the same share for every vertex
    n = mesh.n_points
    return sum(np.bincount(tri[:, a], weights=w, minlength=n) for a in range(k))


def _source_values(mesh, f, quad, tri, idx) -> np.ndarray:
    """``f`` at the rule's physical points, (k, q); raises naming elements where it is not finite.

    A case's compiled source (:mod:`femkit.fem.fused`) is evaluated point by point in one pass
    over the cells, without the (m, q) coordinate arrays; otherwise NumPy evaluates ``f`` on them.
    """
    fq = None
    if idx is None:
        from .fused import source_values

        fq = source_values(mesh, f, quad)
    if fq is None:
        coords = quad.physical_points(mesh, tri)  # d arrays (m, q)
        fq = evaluate_callable(f, *coords, name="f")
    if not np.isfinite(fq).all():
        bad = np.flatnonzero(~np.isfinite(fq).all(axis=1))
        ids = bad if idx is None else idx[bad]
        raise InputError(f"source f is not finite on {len(ids)} element(s), first ids {ids[:10].tolist()}")
    return fq


def _load_numba(mesh, f, quad, idx):
    """One-point rule through the compiled kernel; None when some triangle is degenerate
    (the numpy path then raises naming them)."""
    from ._kernels import load_kernel

    if callable(f) and idx is None:  # compiled source: the whole vector in one fused pass
        from .fused import barycentric_load

        F = barycentric_load(mesh, f, quad)
        if F is not None:
            return F
    if callable(f):
        tri = mesh.cells if idx is None else mesh.cells[idx]
        fvals = _source_values(mesh, f, quad, tri, idx)[:, 0]
    else:
        fvals = _scalar(f)
    return load_kernel(mesh, idx, fvals)


def _areas(mesh, tri):
    if tri.shape[1] == 4:
        from ..mesh.mesh import signed_volumes

        return np.abs(signed_volumes(mesh.points, tri))
    px, py = mesh.points[:, 0].copy(), mesh.points[:, 1].copy()
    x = [np.take(px, tri[:, a]) for a in range(3)]
    y = [np.take(py, tri[:, a]) for a in range(3)]
    return 0.5 * np.abs((x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]))


def _scalar(f) -> float:
    try:
        val = float(f)
    except (TypeError, ValueError):
        raise InputError(f"source f must be a number or a callable f(x, y[, z]), got {f!r}") from None
    if not np.isfinite(val):
        raise InputError(f"source f must be finite, got {val}")
    return val
