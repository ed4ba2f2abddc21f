"""Small meshes as plain arrays for the solids tests (gmsh-free), and deformation helpers."""

from __future__ import annotations

import itertools

import numpy as np

from femkit.mesh.structured import grid_triangles


def tet_box(nx: int, ny: int, nz: int, lengths=(1.0, 1.0, 1.0)):
    """Points and positively oriented tetrahedra of a box: every hexahedron into the 6
    tetrahedra around its main diagonal (Kuhn's subdivision, conforming across cells)."""
    xs, ys, zs = (np.linspace(0.0, L, k + 1) for L, k in zip(lengths, (nx, ny, nz)))
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])

    def node(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"))
    tets = []
    for perm in itertools.permutations(range(3)):
        corner = np.zeros((len(i), 3), dtype=np.int64)
        verts = [node(i, j, k)]
        for axis in perm:
            corner[:, axis] += 1
            verts.append(node(i + corner[:, 0], j + corner[:, 1], k + corner[:, 2]))
        tets.append(np.column_stack(verts))
    tets = np.concatenate(tets)
    e = pts[tets[:, 1:]] - pts[tets[:, :1]]
    flip = np.linalg.det(e) < 0
    tets[flip, 1], tets[flip, 2] = tets[flip, 2].copy(), tets[flip, 1].copy()
    return pts, tets


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
