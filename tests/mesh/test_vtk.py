"""femkit's one VTK writer (femkit.mesh.vtk): what is written reads back the same."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh.vtk import write_cells, write_collection, write_parallel_index

POINTS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
CELLS = [("triangle", np.array([[0, 1, 2], [0, 2, 3]])), ("line", np.array([[0, 1]]))]


def test_cells_and_data_read_back(tmp_path):
    path = write_cells(tmp_path / "sub" / "m.vtu", POINTS, CELLS,
                       point_data={"u": np.arange(4.0), "v": np.ones((4, 3))},
                       cell_data={"tag": [np.array([1, 2], np.int32), np.array([7], np.int32)]})
    m = meshio.read(path)
    assert np.array_equal(m.points, np.column_stack([POINTS, np.zeros(4)]))  # padded to 3D
    assert [(c.type, c.data.tolist()) for c in m.cells] == [(k, c.tolist()) for k, c in CELLS]
    assert np.array_equal(m.point_data["u"], np.arange(4.0))
    assert [a.tolist() for a in m.cell_data["tag"]] == [[1, 2], [7]]


@pytest.mark.parametrize("rows", [1 << 20, 2], ids=["one-block", "blocks-of-2-rows"])
def test_cell_ids_are_int32_and_read_back_across_blocks(tmp_path, monkeypatch, rows):
    """Connectivity and offsets are Int32 when the ids fit (half the bytes of Int64), converted
    a block of rows at a time: the blocks join into the same cells and offsets."""
    import femkit.mesh.vtk as vtk

    monkeypatch.setattr(vtk, "_ROWS", rows)
    tris = np.array([[0, 1, 2], [0, 2, 3], [1, 2, 3], [0, 1, 3], [2, 3, 0]], np.int64)
    cells = [("triangle", tris), ("line", np.array([[0, 1], [1, 2], [2, 3]], np.int64))]
    path = write_cells(tmp_path / "m.vtu", POINTS, cells, point_data={"u": np.arange(4.0)})
    arrays = {a.get("Name"): a.get("type") for a in vtk.vtu_header(path).iter("DataArray")}
    assert arrays["connectivity"] == arrays["offsets"] == "Int32"
    m = meshio.read(path)
    assert [(c.type, c.data.tolist()) for c in m.cells] == [(k, c.tolist()) for k, c in cells]
    assert np.array_equal(m.point_data["u"], np.arange(4.0))


@pytest.mark.parametrize("rows", [1 << 20, 2], ids=["one-block", "blocks-of-2-rows"])
def test_a_broadcast_constant_is_written_without_its_copies(tmp_path, monkeypatch, rows):
    """A constant cell field (a constant coefficient) passed as a broadcast view is written a
    block of rows at a time and reads back as the full array."""
    import femkit.mesh.vtk as vtk

    monkeypatch.setattr(vtk, "_ROWS", rows)
    tris = np.array([[0, 1, 2], [0, 2, 3], [1, 2, 3]], np.int64)
    kappa = np.broadcast_to(np.float64(2.5), (3,))
    path = write_cells(tmp_path / "m.vtu", POINTS, [("triangle", tris)],
                       cell_data={"kappa": [kappa], "tag": [np.array([4, 5, 6], np.int32)]})
    m = meshio.read(path)
    assert m.cell_data["kappa"][0].tolist() == [2.5, 2.5, 2.5]
    assert m.cell_data["tag"][0].tolist() == [4, 5, 6]


@pytest.mark.parametrize("kw, match", [
    (dict(point_data={"u": np.zeros(3)}), "point_data 'u' has 3 rows"),
    (dict(cell_data={"c": [np.zeros(2), np.zeros(2)]}), r"cell_data 'c' has \[2, 2\] rows"),
], ids=["point-rows", "cell-rows"])
def test_mismatched_data_is_a_mesh_error(tmp_path, kw, match):
    with pytest.raises(MeshError, match=match):
        write_cells(tmp_path / "m.vtu", POINTS, CELLS, **kw)
    assert not (tmp_path / "m.vtu").exists()


def test_unwritable_format_is_a_mesh_error(tmp_path):
    with pytest.raises(MeshError, match="cannot write mesh file"):
        write_cells(tmp_path / "m.unknown_ext", POINTS, CELLS)


def test_collection_lists_files_at_times(tmp_path):
    path = write_collection(tmp_path / "s.pvd", [0.0, 0.5], ["f/a.vtu", "f/b&c.vtu"])
    rows = ET.parse(path).getroot().findall("Collection/DataSet")
    assert [(float(r.get("timestep")), r.get("file")) for r in rows] == [(0.0, "f/a.vtu"),
                                                                        (0.5, "f/b&c.vtu")]


def test_parallel_index_declares_the_pieces_arrays(tmp_path):
    piece = write_cells(tmp_path / "s_p0.vtu", POINTS, CELLS[:1], point_data={"u": np.zeros(4)},
                        cell_data={"rank": [np.zeros(2, np.int32)]})
    index = write_parallel_index(tmp_path / "s.pvtu", piece, ["s_p0.vtu", "s_p1.vtu"])
    grid = ET.parse(index).getroot().find("PUnstructuredGrid")
    assert [p.get("Source") for p in grid.findall("Piece")] == ["s_p0.vtu", "s_p1.vtu"]
    assert [a.get("Name") for a in grid.find("PPointData")] == ["u"]
    assert [a.get("Name") for a in grid.find("PCellData")] == ["rank"]
    assert not list(tmp_path.glob("*.tmp"))


def test_importing_the_mesh_package_loads_no_writer_modules():
    """meshio and the XML modules (xml.sax pulls in urllib and ssl) load only when writing."""
    import subprocess
    import sys

    from cost_probe import child_env

    code = ("import sys, femkit.mesh, femkit.mesh.vtk; "
            "print(sorted(m for m in ('meshio', 'xml.sax', 'xml.etree.ElementTree', 'ssl') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=child_env())
    assert out.stdout.strip() == "[]"
