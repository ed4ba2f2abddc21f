"""gmsh solid geometries and tetrahedral mesh files (.msh 2.2 / 4.1, .vtu, .geo)."""

import math

import numpy as np
import pytest

from femkit.errors import InputError, MeshError
from femkit.mesh import generate, geo_file, quality, read_mesh, validate, write_mesh
from femkit.mesh.faces import boundary_faces_topological

pytest.importorskip("gmsh")

H = 0.35

# geometry, params, exact volume, relative tolerance (curved boundaries are faceted), groups
# whose union is the boundary
CASES = {
    "unit_cube": ({}, 1.0, 1e-12, ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]),
    "box": (dict(lx=2.0, ly=1.0, lz=0.5), 1.0, 1e-12, ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]),
    "beam": (dict(length=4.0), 4.0, 1e-12, ["clamped", "tip", "ymin", "ymax", "zmin", "zmax"]),
    "l_shape_3d": ({}, 7.0, 1e-12, ["reentrant", "outer"]),
    "sphere": ({}, 4 / 3 * math.pi, 0.06, ["outer"]),
    "cylinder": (dict(radius=0.5, height=1.0), math.pi * 0.25, 0.03, ["bottom", "top", "side"]),
}


def _key(faces):
    return sorted(map(tuple, np.sort(faces, axis=1)))


@pytest.fixture(scope="module", params=list(CASES))
def case(request):
    params, volume, rtol, parts = CASES[request.param]
    return request.param, generate(request.param, H, **params), volume, rtol, parts


def test_valid_tetrahedra_with_the_right_volume(case):
    name, m, volume, rtol, _ = case
    assert m.dim == 3 and m.n_cells > 50
    validate(m)
    assert (m.signed_volumes() > 0).all()
    assert m.volumes().sum() == pytest.approx(volume, rel=rtol)
    assert quality(m)["min_dihedral"] > 5.0
    assert (m.cell_tags == m.tag("domain")).all()


def test_boundary_group_is_the_whole_boundary_and_parts_cover_it(case):
    _, m, _, _, parts = case
    topo = _key(boundary_faces_topological(m))
    assert _key(m.boundary_facets[m.boundary_tags == m.tag("boundary")]) == topo
    union = np.concatenate([m.boundary_facets[m.boundary_tags == m.tag(p)] for p in parts])
    assert sorted(set(_key(union))) == topo


def test_box_sides_lie_on_their_planes():
    m = generate("box", H, lx=2.0, ly=1.0, lz=0.5, origin=(1.0, -1.0, 0.0))
    lo, hi = np.array([1.0, -1.0, 0.0]), np.array([3.0, 0.0, 0.5])
    for k, name in enumerate(["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]):
        d, upper = divmod(k, 2)
        pts = m.points[m.boundary_facets[m.boundary_tags == m.tag(name)]]
        np.testing.assert_allclose(pts[..., d], hi[d] if upper else lo[d], atol=1e-12)


def test_fichera_reentrant_faces_are_the_removed_octant():
    m = generate("l_shape_3d", H)
    pts = m.points[m.boundary_facets[m.boundary_tags == m.tag("reentrant")]]
    assert (pts >= -1e-12).all() and (pts <= 1 + 1e-12).all()
    on_a_plane = (np.abs(pts) < 1e-12).all(axis=1).any(axis=1)     # each face on x, y or z = 0
    assert on_a_plane.all()
    # the three faces of the octant: area 3
    p = pts
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    assert area == pytest.approx(3.0, rel=1e-12)


def test_bad_parameters_name_the_valid_ones():
    with pytest.raises(InputError, match="valid parameters: radius, height"):
        generate("cylinder", H, diameter=1.0)
    with pytest.raises(InputError, match="radius must be positive"):
        generate("sphere", H, radius=-1.0)


@pytest.fixture(scope="module")
def tagged_box():
    return generate("box", 0.4, lx=1.0, ly=2.0, lz=1.0)


@pytest.mark.parametrize("suffix, kw", [(".msh", {}), (".msh", {"msh_version": "2.2"}),
                                        (".vtu", {})], ids=["msh41", "msh22", "vtu"])
def test_round_trip(tmp_path, tagged_box, suffix, kw):
    m = tagged_box
    path = tmp_path / f"box{suffix}"
    write_mesh(path, m, **kw)
    r = read_mesh(path)
    assert r.dim == 3
    np.testing.assert_allclose(r.points, m.points, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(r.cells, m.cells)
    np.testing.assert_array_equal(r.cell_tags, m.cell_tags)
    assert r.tag_names == m.tag_names
    for name in ("xmin", "boundary"):
        assert _key(r.boundary_facets[r.boundary_tags == r.tag(name)]) == \
            _key(m.boundary_facets[m.boundary_tags == m.tag(name)])


def test_gmsh_written_msh_volume_is_read(tmp_path):
    """A .geo with physical volumes and surfaces, meshed and saved by gmsh (v2 and v4)."""
    import gmsh

    geo = tmp_path / "block.geo"
    geo.write_text('SetFactory("OpenCASCADE");\nBox(1) = {0, 0, 0, 1, 1, 2};\n'
                   'Physical Volume("solid", 10) = {1};\nPhysical Surface("bottom", 20) = {5};\n'
                   'Physical Surface("top", 21) = {6};\nMesh.MeshSizeMax = 0.5;\n')
    from_geo = geo_file(geo)
    assert from_geo.dim == 3 and from_geo.volumes().sum() == pytest.approx(2.0, rel=1e-12)
    for version in (2.2, 4.1):
        msh = tmp_path / f"block{version}.msh"
        gmsh.initialize(argv=[], readConfigFiles=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.open(str(geo))
            gmsh.model.mesh.generate(3)
            gmsh.option.setNumber("Mesh.MshFileVersion", version)
            gmsh.write(str(msh))
        finally:
            gmsh.finalize()
        m = read_mesh(msh)
        assert m.dim == 3 and m.volumes().sum() == pytest.approx(2.0, rel=1e-12)
        assert (m.cell_tags == m.tag("solid")).all()
        bottom = m.points[m.boundary_facets[m.boundary_tags == m.tag("bottom")]]
        top = m.points[m.boundary_facets[m.boundary_tags == m.tag("top")]]
        assert np.allclose(bottom[..., 2], 0.0) and np.allclose(top[..., 2], 2.0)


def _write_meshio(path, points, cells, tags=None, field_data=None):
    import meshio

    cd = None if tags is None else {"gmsh:physical": tags, "gmsh:geometrical": tags}
    meshio.write(path, meshio.Mesh(points, cells, cell_data=cd, field_data=field_data or {}),
                 file_format="gmsh22", binary=False)


CUBE = np.array([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [5., 5., 5.], [6., 5., 5.],
                 [5., 6., 5.]])


def test_mixed_dimension_file_is_refused(tmp_path):
    p = tmp_path / "mixed.msh"
    _write_meshio(p, CUBE, [("tetra", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[4, 5, 6]]))],
                  tags=[np.array([1]), np.array([2])])
    with pytest.raises(MeshError, match=r"mixes dimensions: 1 triangle\(s\) are not faces of its 1 tetrahedra"):
        read_mesh(p)


def test_tetrahedra_outside_every_physical_volume_are_refused(tmp_path):
    p = tmp_path / "loose.msh"
    pts = np.vstack([CUBE[:4], [[1., 1., 1.]]])
    _write_meshio(p, pts, [("tetra", np.array([[0, 1, 2, 3], [1, 2, 3, 4]]))],
                  tags=[np.array([7, 0])], field_data={"solid": np.array([7, 3])})
    with pytest.raises(MeshError, match=r"1 of 2 tetrahedra belong to no physical volume"):
        read_mesh(p)


def test_geo_volume_without_physical_group_is_refused(tmp_path):
    geo = tmp_path / "two.geo"
    geo.write_text('SetFactory("OpenCASCADE");\nBox(1) = {0, 0, 0, 1, 1, 1};\n'
                   'Box(2) = {2, 0, 0, 1, 1, 1};\nPhysical Volume("solid", 1) = {1};\n')
    with pytest.raises(MeshError, match=r"volume\(s\) 2 belong to no physical volume"):
        geo_file(geo, h=0.5)


def test_surface_only_file_says_no_tetrahedra(tmp_path):
    p = tmp_path / "shell.msh"
    _write_meshio(p, CUBE[:4], [("triangle", np.array([[0, 1, 2], [0, 1, 3]]))])
    with pytest.raises(MeshError, match="holds no tetrahedra"):
        read_mesh(p)
