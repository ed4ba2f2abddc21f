"""Test meshes built from arrays (no gmsh): structured unit squares and scikit-fem's MeshTri."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.mesh import Mesh, structured_mesh
from femkit.mesh.structured import SIDES

def unit_square(n: int, *, diagonal: str = "alternating") -> Mesh:
    """Structured triangulation of [0, 1]^2 with n x n cells, sides tagged bottom/right/top/left.

    Cells with ``x_cell < 0.5`` get cell tag 1, the others 2 (group names ``west``/``east``).
    """
    m = structured_mesh(n, n, diagonal=diagonal)
    cell_tags = np.where(m.centroids()[:, 0] < 0.5, 1, 2)
    return Mesh(m.points, m.triangles, cell_tags=cell_tags, boundary_edges=m.boundary_edges,
                boundary_tags=m.boundary_tags, tag_names=dict(SIDES, west=1, east=2))


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
