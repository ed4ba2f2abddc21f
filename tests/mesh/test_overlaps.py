"""Overlapping and duplicated elements are refused naming them (issue 17: a unit square with one
triangle listed twice was accepted, area 1.03125 and the solution off by 7.5e-3), and a mesh's
unused nodes are dropped with a note that says so."""

import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh import Mesh, validate
from femkit.mesh.structured import structured_box, structured_mesh
from femkit.mesh.validate import check_overlaps, drop_unreferenced


def _with(mesh: Mesh, extra) -> Mesh:
    return Mesh(points=mesh.points, cells=np.vstack([mesh.cells, np.atleast_2d(extra)]))


@pytest.mark.parametrize("diagonal", ["uniform", "alternating"])
def test_valid_structured_meshes_pass(diagonal):
    m = structured_mesh(6, 5, 2.0, 1.0, diagonal=diagonal)
    check_overlaps(validate(m))


def test_valid_tetrahedral_box_and_generated_meshes_pass():
    check_overlaps(validate(structured_box(3, 2, 2, (1.0, 2.0, 0.5))))
    from femkit.mesh import generate

    for name in ("l_shape", "annulus", "square_with_inclusion"):
        check_overlaps(validate(generate(name, 0.2)))


@pytest.mark.parametrize("rotate", [(0, 1, 2), (1, 2, 0), (0, 2, 1)],
                         ids=["same", "rotated", "reversed"])
def test_a_triangle_listed_twice_is_named(rotate):
    m = structured_mesh(4, 4)
    bad = _with(m, m.cells[5, list(rotate)])
    assert abs(np.abs(bad.signed_volumes()).sum() - 1.03125) < 1e-14  # the area
    with pytest.raises(MeshError, match=r"share their node set.*element ids 5 = 32$"):
        validate(bad)


def test_a_tetrahedron_listed_twice_is_named():
    b = structured_box(2, 2, 2)
    with pytest.raises(MeshError, match=r"tetrahedron\(s\) share their node set.*ids 3 = 48"):
        validate(_with(b, b.cells[3]))


def test_a_triangle_folded_over_its_neighbour_is_refused_with_the_seam_elements():
    # the unit square split into (0,1,2), (0,2,3); a third triangle (0,1,3) covers half of both
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ok = Mesh(points=pts, triangles=np.array([[0, 1, 2], [0, 2, 3]]))
    check_overlaps(validate(ok))
    bad = Mesh(points=pts, triangles=np.array([[0, 1, 2], [0, 2, 3], [0, 1, 3]]))
    with pytest.raises(MeshError, match=r"total area 1.5 differs from the area 0.5 enclosed by the "
                                        r"mesh boundary; element ids 0, 1, 2"):
        validate(bad)


def test_two_tetrahedra_on_the_same_side_of_a_face_are_refused():
    # (0,1,2,3) and (0,1,2,4) both above the face z = 0: they overlap near it
    pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.2, 0.2, 0.5]])
    below = pts.copy()
    below[4, 2] = -0.5  # node 4 under the face
    ok = Mesh(points=below, cells=np.array([[0, 1, 2, 3], [0, 2, 1, 4]]))
    check_overlaps(validate(ok))   # one below the face, one above: glued, not overlapping
    bad = Mesh(points=pts, cells=np.array([[0, 1, 2, 3], [0, 1, 2, 4]]))
    with pytest.raises(MeshError, match=r"overlapping tetrahedra: their total volume 0.25 "
                                        r"differs .* element ids 0, 1$"):
        validate(bad)


def test_enclosed_area_of_a_mesh_with_a_hole_counts_the_hole_out():
    from femkit.mesh import generate

    m = validate(generate("annulus", 0.1, r_inner=0.3, r_outer=1.0))
    check_overlaps(m)  # the inner boundary runs clockwise: its area is subtracted


def test_drop_unreferenced_says_what_it_dropped():
    m = structured_mesh(2, 2)
    pts = np.vstack([m.points, [[5.0, 5.0], [6.0, 6.0]]])
    kept, note = drop_unreferenced(Mesh(points=pts, triangles=m.cells))
    assert kept.n_points == m.n_points and np.array_equal(kept.cells, m.cells)
    assert note == "2 nodes used by no triangle dropped (node ids 9, 10)"
    assert drop_unreferenced(m) == (m, None)
