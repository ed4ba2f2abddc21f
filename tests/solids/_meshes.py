"""Small meshes as plain arrays for the solids tests (gmsh-free), and deformation helpers."""

from __future__ import annotations

import numpy as np

from femkit.mesh.structured import grid_triangles, structured_box


def tet_box(nx: int, ny: int, nz: int, lengths=(1.0, 1.0, 1.0)):
    """Points and positively oriented tetrahedra of femkit's structured box (Kuhn's cut)."""
    mesh = structured_box(nx, ny, nz, lengths)
    return mesh.points, mesh.cells


def tri_rect(nx: int, ny: int, width: float = 1.0, height: float = 1.0, diagonal: str = "alternating"):
    """Points and CCW triangles of an ``nx x ny``-cell rectangle."""
    xs, ys = np.linspace(0.0, width, nx + 1), np.linspace(0.0, height, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    return np.column_stack([X.ravel(), Y.ravel()]), grid_triangles(nx + 1, ny + 1, diagonal=diagonal)


def random_rotation(rng, d: int) -> np.ndarray:
    Q, R = np.linalg.qr(rng.standard_normal((d, d)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def mesh_by_dim(dim: int):
    return tri_rect(3, 2) if dim == 2 else tet_box(2, 1, 1)


def facets_on(points, cells, axis: int, value: float, tol: float = 1e-12):
    """Boundary facets (edges in 2D, triangles in 3D) of ``cells`` lying on the plane
    ``points[:, axis] == value``."""
    d = points.shape[1]
    nv = d + 1
    faces = np.concatenate([np.delete(cells, k, axis=1) for k in range(nv)])
    on = np.all(np.abs(points[faces, axis] - value) <= tol, axis=1)
    return faces[on]


def nodes_on(points, axis: int, value: float, tol: float = 1e-12):
    return np.flatnonzero(np.abs(points[:, axis] - value) <= tol)


#: finite-difference steps of the derivative checks (Kim & Eberle's protocol: the smallest
#: relative difference over the sweep counts)
STEPS = 10.0 ** -np.arange(4, 9)


def min_rel(exact, approx_of_h) -> float:
    """The smallest relative difference ``|approx(h) - exact| / |exact|`` over :data:`STEPS`."""
    scale = max(np.linalg.norm(exact), 1e-300)
    return min(np.linalg.norm(approx_of_h(h) - exact) / scale for h in STEPS)


def assembled_fd_errors(body, x) -> tuple[float, float]:
    """:func:`min_rel` of a body's assembled gradient against central differences of its
    energy, and of its Hessian against central differences of its gradient, at ``x``."""
    _, g, H, _ = body.evaluate(x)
    flat = np.asarray(x, dtype=float).ravel()
    n = flat.size

    def grad_fd(h):
        out = np.zeros(n)
        for i in range(n):
            e = np.zeros(n)
            e[i] = h
            out[i] = (body.energy(flat + e) - body.energy(flat - e)) / (2 * h)
        return out

    def hess_fd(h):
        cols = []
        for i in range(n):
            e = np.zeros(n)
            e[i] = h
            cols.append((body.gradient(flat + e) - body.gradient(flat - e)).ravel() / (2 * h))
        return np.column_stack(cols)

    return min_rel(g.ravel(), grad_fd), min_rel(H.toarray(), hess_fd)
