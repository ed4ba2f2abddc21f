"""The VTU compression choice: every choice reads back the same arrays, the file says which
compressor it used, and an unknown name is refused with the valid ones."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from femkit.errors import MeshError
from femkit.mesh.vtk import COMPRESSIONS, DEFAULT_COMPRESSION, write_cells

POINTS = np.random.default_rng(1).random((50, 2))
CELLS = [("triangle", np.random.default_rng(2).integers(0, 50, (80, 3)))]
U = np.random.default_rng(3).random(50)


@pytest.mark.parametrize("compression", sorted(COMPRESSIONS))
def test_every_compression_reads_back_the_same(tmp_path, compression):
    path = write_cells(tmp_path / "m.vtu", POINTS, CELLS, point_data={"u": U}, compression=compression)
    m = meshio.read(path)
    assert np.array_equal(m.point_data["u"], U)
    assert np.array_equal(m.cells[0].data, CELLS[0][1])
    root = ET.parse(path).getroot()
    expected = {"none": None, "zlib": "vtkZLibDataCompressor", "lzma": "vtkLZMADataCompressor"}
    assert root.attrib.get("compressor") == expected[compression]


def test_default_is_uncompressed_and_larger_than_zlib(tmp_path):
    assert DEFAULT_COMPRESSION == "none"
    plain = write_cells(tmp_path / "a.vtu", POINTS, CELLS, point_data={"u": np.zeros(50)})
    packed = write_cells(tmp_path / "b.vtu", POINTS, CELLS, point_data={"u": np.zeros(50)},
                         compression="zlib")
    assert "compressor" not in ET.parse(plain).getroot().attrib
    assert plain.stat().st_size > packed.stat().st_size


def test_unknown_compression_lists_the_valid_ones(tmp_path):
    with pytest.raises(MeshError, match="unknown VTU compression 'lz5'; valid: none, zlib, lzma"):
        write_cells(tmp_path / "m.vtu", POINTS, CELLS, compression="lz5")
    assert not (tmp_path / "m.vtu").exists()
