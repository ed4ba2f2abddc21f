"""The one mesh record: triangles and tetrahedra, aliases, dimension errors."""

import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh import Mesh

TRI_PTS = np.array([[0., 0.], [1., 0.], [0., 1.]])
TET_PTS = np.array([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]])


def _random_tets(state: int, m: int = 20):
    rng = np.random.default_rng(state)
    pts = rng.standard_normal((4 * m, 3))
    return pts, np.arange(4 * m).reshape(m, 4)


def test_width_decides_dimension():
    tri, tet = Mesh(TRI_PTS, [[0, 1, 2]]), Mesh(TET_PTS, [[0, 1, 2, 3]])
    assert (tri.dim, tri.n_cells, tri.points.shape) == (2, 1, (3, 2))
    assert (tet.dim, tet.n_cells, tet.points.shape) == (3, 1, (4, 3))
    assert tet.boundary_facets.shape == (0, 3) and tri.boundary_facets.shape == (0, 2)


def test_signed_volumes_equal_determinants():
    pts, tets = _random_tets(0)
    m = Mesh(pts, tets)
    d = pts[tets[:, 1:]] - pts[tets[:, :1]]
    np.testing.assert_allclose(m.signed_volumes(), np.linalg.det(d) / 6.0, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(m.volumes(), np.abs(np.linalg.det(d)) / 6.0, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(m.centroids(), pts[tets].sum(axis=1) / 4, rtol=1e-14)


def test_triangle_record_unchanged():
    pts3 = np.column_stack([TRI_PTS, [5.0, 6.0, 7.0]])   # planar mesh given with z: z dropped
    m = Mesh(points=pts3, triangles=[[0, 1, 2]], boundary_edges=[[0, 1]], boundary_tags=[3],
             tag_names={"bottom": 3})
    assert m.points.shape == (3, 2)
    assert m.triangles is m.cells and m.boundary_edges is m.boundary_facets
    assert m.n_triangles == 1 and m.areas()[0] == pytest.approx(0.5, rel=1e-15)
    assert m.signed_areas()[0] == m.signed_volumes()[0]
    assert m.tag("bottom") == 3


def test_tetrahedra_aliases():
    m = Mesh(points=TET_PTS, tetrahedra=[[0, 1, 2, 3]], boundary_faces=[[0, 2, 1]],
             boundary_tags=[1], tag_names={"zmin": 1})
    assert m.tetrahedra is m.cells and m.boundary_faces is m.boundary_facets
    assert m.volumes()[0] == pytest.approx(1 / 6, rel=1e-15)


@pytest.mark.parametrize("attr", ["triangles", "n_triangles", "boundary_edges"])
def test_2d_names_on_3d_mesh_name_the_dimension(attr):
    m = Mesh(TET_PTS, [[0, 1, 2, 3]])
    with pytest.raises(MeshError, match=r"2D meshes .*this mesh is 3D"):
        getattr(m, attr)


@pytest.mark.parametrize("method", ["areas", "signed_areas"])
def test_2d_methods_on_3d_mesh_name_the_dimension(method):
    with pytest.raises(MeshError, match=r"this mesh is 3D"):
        getattr(Mesh(TET_PTS, [[0, 1, 2, 3]]), method)()


@pytest.mark.parametrize("attr", ["tetrahedra", "boundary_faces"])
def test_3d_names_on_2d_mesh_name_the_dimension(attr):
    with pytest.raises(MeshError, match=r"3D meshes .*this mesh is 2D"):
        getattr(Mesh(TRI_PTS, [[0, 1, 2]]), attr)


@pytest.mark.parametrize("kwargs, match", [
    (dict(points=TET_PTS, triangles=[[0, 1, 2, 3]]), "triangles= is for 2D"),
    (dict(points=TRI_PTS, tetrahedra=[[0, 1, 2]]), "tetrahedra= is for 3D"),
    (dict(points=TET_PTS, cells=[[0, 1, 2, 3]], boundary_edges=[[0, 1]]), "boundary_edges= is for 2D"),
    (dict(points=TET_PTS, cells=[[0, 1, 2, 3]], boundary_facets=[[0, 1]]), r"shape \(k, 3\)"),
    (dict(points=TRI_PTS[:, :1], cells=[[0, 1, 2]]), r"shape \(n, 2\)"),
    (dict(points=TRI_PTS, cells=[[0, 1]]), r"\(m, 3\) \(triangles\) or \(m, 4\)"),
    (dict(points=TET_PTS, cells=[[0, 1, 2, 3]], cell_tags=[1, 2]), "one entry per tetrahedron"),
], ids=["tri-alias-4-cols", "tet-alias-3-cols", "edges-alias-3d", "facet-width", "points-width",
        "cell-width", "cell-tags-length"])
def test_bad_shapes_are_mesh_errors(kwargs, match):
    with pytest.raises(MeshError, match=match):
        Mesh(**kwargs)


def test_frozen():
    m = Mesh(TET_PTS, [[0, 1, 2, 3]])
    with pytest.raises(AttributeError):
        m.cells = None
