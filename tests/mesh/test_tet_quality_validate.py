"""Quality numbers and validation of tetrahedral meshes."""

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError, MeshError
from femkit.mesh import Mesh, quality, validate
from femkit.mesh.quality import dihedral_angles, radius_ratios
from femkit.mesh.validate import remove_unreferenced

CORNER = np.array([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]])


def test_corner_tetrahedron_angles():
    ang = np.sort(dihedral_angles(CORNER[None])[0])
    expect = np.sort([90.0] * 3 + [np.degrees(np.arccos(1 / np.sqrt(3)))] * 3)
    np.testing.assert_allclose(ang, expect, rtol=1e-12)


def test_regular_tetrahedron():
    p = np.array([[1., 1., 1.], [1., -1., -1.], [-1., 1., -1.], [-1., -1., 1.]])
    q = quality(validate(Mesh(p, [[0, 1, 2, 3]])))
    assert q["min_dihedral"] == pytest.approx(np.degrees(np.arccos(1 / 3)), rel=1e-12)
    assert q["min_radius_ratio"] == pytest.approx(1.0, rel=1e-12)
    assert q["volume"] == pytest.approx(8 / 3, rel=1e-12)


def test_radius_ratio_of_corner_tetrahedron():
    # inradius 1 / (3 + sqrt 3), circumradius sqrt(3) / 2
    expect = 3 * (1 / (3 + np.sqrt(3))) / (np.sqrt(3) / 2)
    assert radius_ratios(CORNER[None])[0] == pytest.approx(expect, rel=1e-12)


def test_negative_tetrahedra_are_reoriented():
    m = validate(Mesh(CORNER, [[0, 2, 1, 3]]))
    assert m.signed_volumes()[0] == pytest.approx(1 / 6, rel=1e-15)


@pytest.mark.parametrize("points, cells, error, match", [
    (np.vstack([CORNER[:3], [0.5, 0.5, 0.0]]), [[0, 1, 2, 3]], DegenerateMeshError,
     r"1 degenerate tetrahedron\(s\) \(volume <= .* longest edge\^3\): element ids 0"),
    (CORNER, [[0, 1, 1, 3]], DegenerateMeshError, r"tetrahedron\(s\) repeat a vertex: element ids 0"),
    (np.vstack([CORNER, [[5., 5., 5.]]]), [[0, 1, 2, 3]], MeshError, r"unreferenced node\(s\) .*node ids 4"),
    (np.vstack([CORNER, [[0., 0., 0.]]]), [[0, 1, 2, 3], [4, 2, 1, 3]], MeshError,
     "coincident nodes: 0=4"),
    (CORNER, [[0, 1, 2, 7]], MeshError, r"refer to nodes outside 0..3"),
], ids=["flat", "repeated-vertex", "unused-node", "duplicate-node", "index-out-of-range"])
def test_validate_names_the_problem(points, cells, error, match):
    with pytest.raises(error, match=match):
        validate(Mesh(points, cells))


def test_remove_unreferenced_3d():
    m = remove_unreferenced(Mesh(np.vstack([[[9., 9., 9.]], CORNER]), [[1, 2, 3, 4]],
                                 boundary_faces=[[1, 3, 2]], boundary_tags=[1]))
    assert m.n_points == 4 and m.cells.tolist() == [[0, 1, 2, 3]]
    assert m.boundary_faces.tolist() == [[0, 2, 1]]
