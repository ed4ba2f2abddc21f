"""Validation errors name what is wrong and where."""

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError, MeshError
from femkit.mesh import Mesh, check_tags, generate, validate
from femkit.mesh.validate import remove_unreferenced


@pytest.fixture(scope="module")
def square():
    return generate("unit_square", 0.25)


def _with(mesh, **kw):
    d = dict(points=mesh.points, triangles=mesh.triangles, cell_tags=mesh.cell_tags,
             boundary_edges=mesh.boundary_edges, boundary_tags=mesh.boundary_tags,
             tag_names=mesh.tag_names)
    d.update(kw)
    return Mesh(**d)


def test_valid_mesh_passes(square):
    assert validate(square) is square


def test_degenerate_triangles_named(square):
    n, m = square.n_points, square.n_triangles
    extra = np.array([[2.0, 0.0], [3.0, 0.0], [4.0, 0.0], [2.0, 1.0], [2.0, 1.0 + 1e-14]])
    bad = _with(square, points=np.vstack([square.points, extra]),
                triangles=np.vstack([square.triangles, [[n, n + 1, n + 2], [n + 3, n, n + 4]]]),
                cell_tags=None)
    with pytest.raises(DegenerateMeshError) as info:
        validate(bad)
    assert info.value.element_ids == [m, m + 1]
    assert f"2 degenerate triangle(s)" in str(info.value) and f"{m}, {m + 1}" in str(info.value)


def test_many_degenerate_ids_truncated():
    pts = np.column_stack([np.arange(40.0), np.zeros(40)])
    tri = np.column_stack([np.arange(0, 39, 3), np.arange(1, 40, 3), np.arange(2, 40, 3)])
    with pytest.raises(DegenerateMeshError, match=r"13 degenerate.*\(13 in all\)") as info:
        validate(Mesh(points=pts[:39], triangles=tri))
    assert len(info.value.element_ids) == 13


def test_repeated_vertex(square):
    tri = square.triangles.copy()
    tri[5, 2] = tri[5, 0]
    with pytest.raises(DegenerateMeshError, match="repeat a vertex: element ids 5") as info:
        validate(_with(square, triangles=tri))
    assert info.value.element_ids == [5]


def test_out_of_range_index(square):
    tri = square.triangles.copy()
    tri[3, 1] = square.n_points + 7
    with pytest.raises(MeshError, match="outside.*element ids 3"):
        validate(_with(square, triangles=tri))


def test_unreferenced_node_and_fix(square):
    pts = np.insert(square.points, 4, [[5.0, 5.0]], axis=0)
    shift = lambda a: np.where(a >= 4, a + 1, a)  # noqa: E731
    bad = _with(square, points=pts, triangles=shift(square.triangles),
                boundary_edges=shift(square.boundary_edges))
    with pytest.raises(MeshError, match="1 unreferenced node.*node ids 4") as info:
        validate(bad)
    assert "remove_unreferenced" in str(info.value)
    fixed = validate(remove_unreferenced(bad))
    np.testing.assert_array_equal(fixed.points, square.points)
    np.testing.assert_array_equal(fixed.triangles, square.triangles)
    np.testing.assert_array_equal(fixed.boundary_edges, square.boundary_edges)


def test_duplicate_node(square):
    n = square.n_points
    v = int(square.triangles[0, 0])
    tri = square.triangles.copy()
    tri[0, 0] = n  # triangle 0 uses a copy of node v
    bad = _with(square, points=np.vstack([square.points, square.points[v]]), triangles=tri)
    with pytest.raises(MeshError, match=f"1 pair\\(s\\) of coincident nodes: {min(v, n)}={max(v, n)}"):
        validate(bad)


def test_clockwise_is_reoriented(square):
    cw = _with(square, triangles=square.triangles[:, [0, 2, 1]])
    out = validate(cw)
    assert (out.signed_areas() > 0).all()
    np.testing.assert_allclose(out.areas(), square.areas())


def test_no_triangles():
    with pytest.raises(MeshError, match="no triangles"):
        validate(Mesh(points=np.zeros((3, 2)), triangles=np.zeros((0, 3))))


def test_check_tags(square):
    assert check_tags(square, ["left", "top"]) == [square.tag("left"), square.tag("top")]
    assert check_tags(square, "domain", kind="cell") == [square.tag("domain")]
    with pytest.raises(MeshError) as info:
        check_tags(square, ["left", "lft"])
    msg = str(info.value)
    assert "'lft'" in msg and all(n in msg for n in ("left", "right", "bottom", "top", "boundary"))
    assert "domain" not in msg  # a cell group is not offered as a boundary tag
    with pytest.raises(MeshError, match="carried by no edge"):
        check_tags(square, "domain")
    with pytest.raises(MeshError, match="no cell tag 'inclusion'.*available cell tags: domain"):
        check_tags(square, "inclusion", kind="cell")
