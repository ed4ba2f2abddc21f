"""meshio read/write: round trips, gmsh-written files, lean import, bad files."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh import Mesh, generate, read_mesh, write_mesh

PLATE = Path(__file__).resolve().parents[2] / "meshes" / "plate_with_hole.msh"
PLATE_GEO = PLATE.with_suffix(".geo")


def _edge_records(m):
    """Boundary edges as a sorted list of (tag, a, b), order-free comparison."""
    return sorted(zip(m.boundary_tags.tolist(), *m.boundary_edges.T.tolist()))


def assert_same_mesh(a, b):
    np.testing.assert_allclose(a.points, b.points, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.cell_tags, b.cell_tags)
    assert _edge_records(a) == _edge_records(b)
    assert a.tag_names == b.tag_names


@pytest.fixture(scope="module")
def meshes():
    return {"inclusion": generate("square_with_inclusion", 0.2),
            "annulus": generate("annulus", 0.2)}


@pytest.mark.parametrize("name", ["inclusion", "annulus"])
@pytest.mark.parametrize("fname, kw", [
    ("m.msh", {}), ("m.msh", {"msh_version": "2.2"}), ("m.msh", {"msh_version": "2.2", "binary": True}),
    ("m.vtu", {}), ("m.xdmf", {}),
], ids=["msh41", "msh22", "msh22-binary", "vtu", "xdmf"])
def test_round_trip(tmp_path, meshes, name, fname, kw):
    m = meshes[name]
    path = tmp_path / fname
    data = {} if "msh_version" in kw else dict(  # msh 2.2 carries no data
        point_data={"u": m.points[:, 0] ** 2},
        cell_data={"kappa": np.where(m.cell_tags == m.cell_tags[0], 1.0, 1e6)})
    write_mesh(path, m, **data, **kw)
    assert_same_mesh(read_mesh(path), m)


def test_data_survive_in_file(tmp_path, meshes):
    import meshio
    m = meshes["annulus"]
    u = np.sin(m.points[:, 0])
    for ext in ("msh", "vtu"):
        write_mesh(tmp_path / f"d.{ext}", m, point_data={"u": u})
        np.testing.assert_allclose(np.ravel(meshio.read(tmp_path / f"d.{ext}").point_data["u"]), u,
                                   rtol=1e-15)


def test_gmsh_reads_our_msh41(tmp_path, meshes):
    import gmsh
    m = meshes["inclusion"]
    write_mesh(tmp_path / "g.msh", m)
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(tmp_path / "g.msh"))
        assert len(gmsh.model.mesh.getNodes()[0]) == m.n_points
        names = {gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups()}
        assert names == set(m.tag_names)
    finally:
        gmsh.finalize()


@pytest.fixture(scope="module")
def gmsh_written(tmp_path_factory):
    """The bundled .geo meshed and written by gmsh itself in both msh versions."""
    import gmsh
    d = tmp_path_factory.mktemp("gmsh")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.open(str(PLATE_GEO))
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1)
        gmsh.model.mesh.generate(2)
        for v in ("2.2", "4.1"):
            gmsh.option.setNumber("Mesh.MshFileVersion", float(v))
            gmsh.write(str(d / f"plate{v}.msh"))
    finally:
        gmsh.finalize()
    return d


def test_gmsh_written_v2_and_v4_agree(gmsh_written):
    a, b = read_mesh(gmsh_written / "plate2.2.msh"), read_mesh(gmsh_written / "plate4.1.msh")
    assert_same_mesh(a, b)
    # an edge in several groups is repeated once per group
    counts = {n: int((a.boundary_tags == a.tag(n)).sum()) for n in a.tag_names if n != "plate"}
    assert counts["outer"] == counts["left"] + counts["right"] + counts["bottom"] + counts["top"]
    assert counts["boundary"] == counts["outer"] + counts["hole"]


def test_bundled_plate_mesh():
    m = read_mesh(PLATE)
    assert 1000 <= m.n_triangles <= 3000
    assert set(m.tag_names) == {"left", "right", "bottom", "top", "outer", "hole", "boundary", "plate"}
    assert (m.signed_areas() > 0).all()
    assert abs(m.areas().sum() - (2 - np.pi / 16)) < 0.05**2
    hole = np.unique(m.boundary_edges[m.boundary_tags == m.tag("hole")])
    np.testing.assert_allclose(np.hypot(*(m.points[hole] - [1.0, 0.5]).T), 0.25, rtol=1e-12)
    from femkit.mesh import validate
    validate(m)


def test_reading_msh_does_not_import_gmsh():
    code = ("import sys; from femkit.mesh import read_mesh; m = read_mesh(sys.argv[1]); "
            "assert m.n_triangles > 0; print('gmsh' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code, str(PLATE)], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_import_is_cheap():
    code = "import sys, femkit.mesh; print(sorted(m for m in ('gmsh', 'meshio') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_clockwise_file_is_reoriented(tmp_path):
    import meshio
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    meshio.write(tmp_path / "cw.vtu", meshio.Mesh(pts, [("triangle", np.array([[0, 2, 1], [0, 3, 2]]))]))
    m = read_mesh(tmp_path / "cw.vtu")
    assert m.points.shape == (4, 2)
    assert (m.signed_areas() > 0).all() and m.areas().sum() == pytest.approx(1.0)


def test_missing_file_names_path(tmp_path):
    with pytest.raises(MeshError, match="not found.*nope.msh"):
        read_mesh(tmp_path / "nope.msh")


def test_garbage_file(tmp_path):
    (tmp_path / "bad.msh").write_text("this is not a mesh\n")
    with pytest.raises(MeshError, match=r"bad.msh: not a valid gmsh mesh .*not a gmsh file\?"):
        read_mesh(tmp_path / "bad.msh")


@pytest.mark.parametrize("cells, words", [
    ([("quad", np.array([[0, 1, 2, 3]]))], ["no linear triangles", "quad"]),
    ([("triangle", np.array([[0, 1, 2]])), ("quad", np.array([[0, 1, 2, 3]]))], ["mixes", "quad"]),
], ids=["quad-only", "mixed"])
def test_non_triangle_mesh(tmp_path, cells, words):
    import meshio
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    meshio.write(tmp_path / "q.vtu", meshio.Mesh(pts, cells))
    with pytest.raises(MeshError) as info:
        read_mesh(tmp_path / "q.vtu")
    for w in words:
        assert w in str(info.value)


def test_non_planar_points(tmp_path):
    import meshio
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.5]])
    meshio.write(tmp_path / "z.vtu", meshio.Mesh(pts, [("triangle", np.array([[0, 1, 2]]))]))
    with pytest.raises(MeshError, match="z = 0"):
        read_mesh(tmp_path / "z.vtu")


def test_no_data_in_msh22(tmp_path, meshes):
    m = meshes["annulus"]
    with pytest.raises(MeshError, match="msh 2.2"):
        write_mesh(tmp_path / "x.msh", m, point_data={"u": m.points[:, 0]}, msh_version="2.2")


def test_wrong_data_length(tmp_path, meshes):
    with pytest.raises(MeshError, match="point_data 'u'"):
        write_mesh(tmp_path / "x.vtu", meshes["annulus"], point_data={"u": np.zeros(3)})


def test_untagged_user_mesh_round_trip(tmp_path):
    m = Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]]))
    for ext in ("msh", "vtu"):
        write_mesh(tmp_path / f"u.{ext}", m)
        assert_same_mesh(read_mesh(tmp_path / f"u.{ext}"), m)
