"""The structured tetrahedral box: orientation, volume, conformity, side tags."""

import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh.faces import boundary_faces_topological, faces
from femkit.mesh.structured import SIDES_3D, structured_box

CASES = [((1, 1, 1), (1.0, 1.0, 1.0)), ((3, 2, 4), (1.0, 2.0, 0.5)), ((4, 4, 4), (2.0, 2.0, 2.0))]


@pytest.fixture(params=CASES, ids=["one-cube", "3x2x4-anisotropic", "4x4x4"])
def box(request):
    counts, lengths = request.param
    return counts, np.array(lengths), structured_box(*counts, lengths, origin=(-1.0, 0.5, 2.0))


def test_counts_orientation_volume(box):
    (nx, ny, nz), L, m = box
    assert m.dim == 3
    assert m.n_cells == 6 * nx * ny * nz
    assert m.n_points == (nx + 1) * (ny + 1) * (nz + 1)
    d = m.points[m.cells[:, 1:]] - m.points[m.cells[:, :1]]
    det = np.linalg.det(d)
    assert (det > 0).all()
    # every tetrahedron is a sixth of its cube
    np.testing.assert_allclose(det / 6.0, np.prod(L / (nx, ny, nz)) / 6.0, rtol=1e-12)
    assert m.volumes().sum() == pytest.approx(np.prod(L), rel=1e-13)


def test_conforming(box):
    (nx, ny, nz), _, m = box
    _, tet_faces = faces(m)
    counts = np.bincount(tet_faces.ravel())
    assert counts.max() == 2                       # no face is shared by three tetrahedra
    n_boundary = 2 * 2 * (nx * ny + ny * nz + nx * nz)
    assert (counts == 1).sum() == n_boundary       # and exactly the box's surface is free


def test_side_tags_lie_on_their_planes_and_point_out(box):
    (nx, ny, nz), L, m = box
    lo = np.array([-1.0, 0.5, 2.0])
    hi = lo + L
    for axis, (low_name, high_name) in enumerate([("xmin", "xmax"), ("ymin", "ymax"), ("zmin", "zmax")]):
        for name, plane, sign in ((low_name, lo[axis], -1.0), (high_name, hi[axis], 1.0)):
            f = m.boundary_facets[m.boundary_tags == m.tag(name)]
            other = [n for a, n in zip(range(3), (nx, ny, nz)) if a != axis]
            assert len(f) == 2 * other[0] * other[1]
            np.testing.assert_allclose(m.points[f][..., axis], plane, atol=1e-14)
            p = m.points[f]
            normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            assert (sign * normal[:, axis] > 0).all()
    whole = m.boundary_facets[m.boundary_tags == m.tag("boundary")]
    topo = boundary_faces_topological(m)
    assert sorted(map(tuple, np.sort(whole, 1))) == sorted(map(tuple, np.sort(topo, 1)))
    assert set(m.tag_names) == set(SIDES_3D)


def test_matches_scikit_fem_node_set():
    skfem = pytest.importorskip("skfem")
    m = structured_box(3, 2, 2, (1.0, 1.0, 1.0))
    ref = skfem.MeshTet.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    key = lambda p: sorted(map(tuple, np.round(p, 12)))  # noqa: E731
    assert key(m.points) == key(ref.p.T)
    assert m.volumes().sum() == pytest.approx(1.0, rel=1e-13)


@pytest.mark.parametrize("args", [(0, 1, 1), (1, 1, 1, (1.0, -1.0, 1.0)), (1.5, 1, 1)],
                         ids=["zero-cells", "negative-length", "fractional-count"])
def test_bad_boxes_are_mesh_errors(args):
    with pytest.raises(MeshError):
        structured_box(*args)
