"""Test meshes built from arrays (no gmsh): structured unit squares and scikit-fem's MeshTri."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.mesh import Mesh

SIDES = {"bottom": 1, "right": 2, "top": 3, "left": 4}


def unit_square(n: int, *, diagonal: str = "alternating") -> Mesh:
    """Structured triangulation of [0, 1]^2 with n x n cells, sides tagged bottom/right/top/left.

    Cells with ``x_cell < 0.5`` get cell tag 1, the others 2 (group names ``west``/``east``).
    """
    x = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(x, x, indexing="xy")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    v0 = (j * (n + 1) + i).ravel()
    v1, v2, v3 = v0 + 1, v0 + n + 2, v0 + n + 1
    flip = ((i + j) % 2 == 1).ravel() if diagonal == "alternating" else np.zeros(n * n, bool)
    t_a = np.where(flip[:, None], np.column_stack([v0, v1, v3]), np.column_stack([v0, v1, v2]))
    t_b = np.where(flip[:, None], np.column_stack([v1, v2, v3]), np.column_stack([v0, v2, v3]))
    tri = np.concatenate([t_a, t_b])
    c = pts[tri].mean(axis=1)
    cell_tags = np.where(c[:, 0] < 0.5, 1, 2)
    k = np.arange(n)
    bottom = np.column_stack([k, k + 1])
    right = np.column_stack([k * (n + 1) + n, (k + 1) * (n + 1) + n])
    top = np.column_stack([n * (n + 1) + k, n * (n + 1) + k + 1])
    left = np.column_stack([k * (n + 1), (k + 1) * (n + 1)])
    edges = np.concatenate([bottom, right, top, left])
    tags = np.repeat([1, 2, 3, 4], n)
    names = dict(SIDES, west=1, east=2)
    return Mesh(pts, tri, cell_tags=cell_tags, boundary_edges=edges, boundary_tags=tags, tag_names=names)


def from_skfem(skmesh) -> Mesh:
    """A femkit Mesh with the points and triangles of a scikit-fem MeshTri (same numbering)."""
    return Mesh(skmesh.p.T, skmesh.t.T)


@pytest.fixture
def square8() -> Mesh:
    return unit_square(8)


@pytest.fixture
def sk_mesh():
    """scikit-fem's refined, slightly perturbed unit square and the same mesh as a femkit Mesh."""
    import skfem
    m = skfem.MeshTri().refined(4)
    rng = np.random.default_rng(1)
    p = m.p.copy()
    interior = np.ones(p.shape[1], bool)
    interior[m.boundary_nodes()] = False
    p[:, interior] += 0.01 * rng.standard_normal((2, interior.sum()))
    sk = skfem.MeshTri(p, m.t)
    return sk, from_skfem(sk)


@pytest.fixture
def make_square():
    """The :func:`unit_square` factory (test modules cannot import conftest in importlib mode)."""
    return unit_square
