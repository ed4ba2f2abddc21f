"""Shared helpers of the assembly routines: element subsets and triangle / tetrahedron geometry."""

from __future__ import annotations

import numpy as np

from ..errors import DegenerateMeshError, InputError


def select_elements(mesh, elements) -> np.ndarray | None:
    """Normalise ``elements`` (None, index array or boolean mask) to an index array or None.

    ``None`` means every element.  Raises :class:`~femkit.errors.InputError` for a mask of
    the wrong length or indices out of range.
    """
    if elements is None:
        return None
    m = mesh.n_cells
    sel = np.asarray(elements)
    if sel.dtype == bool:
        if sel.shape != (m,):
            raise InputError(f"element mask must have shape ({m},), got {sel.shape}")
        return np.flatnonzero(sel)
    if sel.size == 0:
        return np.zeros(0, dtype=np.intp)
    if not np.issubdtype(sel.dtype, np.integer):
        raise InputError(f"elements must be an integer index array or a boolean mask, got dtype {sel.dtype}")
    sel = sel.ravel().astype(np.intp, copy=False)
    if sel.min() < -m or sel.max() >= m:
        raise InputError(f"element indices out of range for a mesh of {m} "
                         f"{'triangles' if getattr(mesh, 'dim', 2) == 2 else 'tetrahedra'}")
    return np.where(sel < 0, sel + m, sel)


def triangle_geometry(mesh, idx: np.ndarray | None):
    """Edge vectors opposite each vertex and areas of the selected triangles.

    Returns ``(e, area)`` with ``e`` of shape (m, 3, 2), ``e[:, a]`` the edge opposite vertex ``a``
    (from vertex a+1 to a+2), so that ``grad N_a = rot(e_a) / (2 A_signed)``.
    """
    tri = mesh.triangles if idx is None else mesh.triangles[idx]
    p = mesh.points
    p0, p1, p2 = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    e = np.empty((len(tri), 3, 2))
    np.subtract(p2, p1, out=e[:, 0])
    np.subtract(p0, p2, out=e[:, 1])
    np.subtract(p1, p0, out=e[:, 2])
    signed = 0.5 * (e[:, 2, 0] * (-e[:, 1, 1]) - e[:, 2, 1] * (-e[:, 1, 0]))
    area = np.abs(signed)
    check_areas(area, idx)
    return e, area, signed, tri


def check_areas(area: np.ndarray, idx: np.ndarray | None, dim: int = 2) -> None:
    """Raise :class:`DegenerateMeshError` naming zero-area (or non-finite) triangles, or
    zero-volume tetrahedra with ``dim=3``."""
    bad = ~(area > 0) | ~np.isfinite(area)
    if bad.any():
        local = np.flatnonzero(bad)
        ids = local if idx is None else idx[local]
        what = "triangle(s) with zero or non-finite area" if dim == 2 else \
            "tetrahedron(s) with zero or non-finite volume"
        raise DegenerateMeshError(f"{len(ids)} {what}, first ids: {ids[:10].tolist()}",
                                  element_ids=ids.tolist())


def tetrahedron_geometry(mesh, idx: np.ndarray | None):
    """Barycentric gradients and volumes of the selected tetrahedra.

    Returns ``(grads, volume, signed, tets)``: ``grads`` (m, 4, 3) with ``grads[:, a]`` the
    constant gradient of the P1 basis function of vertex ``a``. With ``a, b, c`` the edges
    from vertex 0 and ``D = a . (b x c) = 6 V_signed``, the rows of the inverse Jacobian are
    ``(b x c, c x a, a x b) / D`` and ``grad N_0 = -(grad N_1 + grad N_2 + grad N_3)``.
    Raises :class:`DegenerateMeshError` naming zero-volume tetrahedra.
    """
    tets = mesh.cells if idx is None else mesh.cells[idx]
    p = mesh.points
    p0 = p[tets[:, 0]]
    a, b, c = p[tets[:, 1]] - p0, p[tets[:, 2]] - p0, p[tets[:, 3]] - p0
    rows = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)   # (m, 3, 3)
    det = np.einsum("md,md->m", a, rows[:, 0])
    volume = np.abs(det) / 6.0
    check_areas(volume, idx, dim=3)
    grads = np.empty((len(tets), 4, 3))
    grads[:, 1:] = rows / det[:, None, None]
    grads[:, 0] = -grads[:, 1:].sum(axis=1)
    return grads, volume, det / 6.0, tets


def simplex_gradients(mesh, idx: np.ndarray | None):
    """``(grads (m, d+1, d), volume (m,), cells)`` of triangles or tetrahedra: the constant
    gradients of the P1 basis functions and the element areas / volumes."""
    if mesh.dim == 3:
        grads, volume, _, cells = tetrahedron_geometry(mesh, idx)
        return grads, volume, cells
    e, area, signed, tri = triangle_geometry(mesh, idx)
    inv = 1.0 / (2.0 * signed)
    grads = np.stack([-e[:, :, 1] * inv[:, None], e[:, :, 0] * inv[:, None]], axis=2)
    return grads, area, tri


def cell_measures(mesh, idx: np.ndarray | None):
    """``(measure (m,), cells)``: the areas or volumes of the selected cells, without their
    gradients (what a mass matrix or a load needs); raises :class:`DegenerateMeshError` naming
    zero-measure cells."""
    from ..mesh.mesh import signed_volumes

    cells = mesh.cells if idx is None else mesh.cells[idx]
    measure = np.abs(signed_volumes(mesh.points, cells))
    check_areas(measure, idx, mesh.dim)
    return measure, cells


def p1_gradients(e: np.ndarray, signed: np.ndarray, ue: np.ndarray) -> np.ndarray:
    """Constant gradient (m, 2) of the P1 function with vertex values ``ue`` (m, 3) on each triangle.

    ``grad N_a = (-e_a,y, e_a,x) / (2 A_signed)``: the edge opposite ``a`` turned towards vertex ``a``
    (``e``, ``signed`` from :func:`triangle_geometry`).
    """
    inv = 1.0 / (2.0 * signed)
    gx = -np.einsum("ma,ma->m", ue, e[:, :, 1]) * inv
    gy = np.einsum("ma,ma->m", ue, e[:, :, 0]) * inv
    return np.stack([gx, gy], axis=1)
