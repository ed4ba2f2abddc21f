"""The VTU compression choice: every choice reads back the same arrays, the file says which
compressor it used, and an unknown name is refused with the valid ones."""

import meshio
import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh.vtk import COMPRESSIONS, DEFAULT_COMPRESSION, vtu_header, write_cells

POINTS = np.random.default_rng(1).random((50, 2))
CELLS = [("triangle", np.random.default_rng(2).integers(0, 50, (80, 3)))]
U = np.random.default_rng(3).random(50)


@pytest.mark.parametrize("compression", sorted(COMPRESSIONS))
def test_every_compression_reads_back_the_same(tmp_path, compression):
    path = write_cells(tmp_path / "m.vtu", POINTS, CELLS, point_data={"u": U}, compression=compression)
    m = meshio.read(path)
    assert np.array_equal(m.point_data["u"], U)
    assert np.array_equal(m.cells[0].data, CELLS[0][1])
    root = vtu_header(path)
    expected = {"none": None, "zlib": "vtkZLibDataCompressor", "lzma": "vtkLZMADataCompressor"}
    assert root.attrib.get("compressor") == expected[compression]


def test_default_is_uncompressed_and_larger_than_zlib(tmp_path):
    assert DEFAULT_COMPRESSION == "none"
    plain = write_cells(tmp_path / "a.vtu", POINTS, CELLS, point_data={"u": np.zeros(50)})
    packed = write_cells(tmp_path / "b.vtu", POINTS, CELLS, point_data={"u": np.zeros(50)},
                         compression="zlib")
    assert "compressor" not in vtu_header(plain).attrib
    assert plain.stat().st_size > packed.stat().st_size


def test_unknown_compression_lists_the_valid_ones(tmp_path):
    with pytest.raises(MeshError, match="unknown VTU compression 'lz5'; valid: none, zlib, lzma"):
        write_cells(tmp_path / "m.vtu", POINTS, CELLS, compression="lz5")
    assert not (tmp_path / "m.vtu").exists()


def test_uncompressed_vtu_reads_back_what_meshio_writes(tmp_path):
    """The raw-appended writer (the default) and meshio's own writer give files meshio reads
    back to the same arrays: two cell blocks, 2D points padded to 3D, scalar and vector point
    data, cell data per block."""
    import meshio

    rng = np.random.default_rng(4)
    cells = [("triangle", rng.integers(0, 50, (80, 3))), ("line", rng.integers(0, 50, (7, 2)))]
    point_data = {"u": U, "v": rng.random((50, 2))}
    cell_data = {"tag": [np.arange(80, dtype=np.int32), np.zeros(7, np.int32)],
                 "kappa": [rng.random(80), rng.random(7)]}
    raw = write_cells(tmp_path / "raw.vtu", POINTS, cells, point_data=point_data,
                      cell_data=cell_data)
    ref = tmp_path / "ref.vtu"
    meshio.write(ref, meshio.Mesh(np.column_stack([POINTS, np.zeros(50)]), cells,
                                  point_data=point_data, cell_data=cell_data), compression=None)
    a, b = meshio.read(raw), meshio.read(ref)
    assert np.array_equal(a.points, b.points)
    assert [(c.type, c.data.tolist()) for c in a.cells] == [(c.type, c.data.tolist()) for c in b.cells]
    for k in point_data:
        assert np.array_equal(a.point_data[k], b.point_data[k]), k
    for k in cell_data:
        assert all(np.array_equal(p, q) for p, q in zip(a.cell_data[k], b.cell_data[k])), k
    assert vtu_header(raw).find("UnstructuredGrid/Piece").get("NumberOfCells") == "87"
