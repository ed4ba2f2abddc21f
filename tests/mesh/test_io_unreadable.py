"""Mesh files that cannot be parsed: one line naming the file, the format and the likely cause."""

import re
from pathlib import Path

import pytest

from femkit.errors import MeshError
from femkit.mesh import read_mesh

PLATE = Path(__file__).resolve().parents[2] / "meshes" / "plate_with_hole.msh"


def _write(tmp_path, name, data: bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(data)
    return p


CASES = [
    ("empty.msh", lambda: b"", "the file is empty"),
    ("truncated.msh", lambda: PLATE.read_bytes()[:3000], "truncated?"),
    ("truncated_in_elements.msh", lambda: PLATE.read_bytes()[: int(PLATE.stat().st_size * 0.9)], "truncated?"),
    ("garbage.msh", lambda: b"hello, this is not a mesh\n", "not a gmsh file?"),
    ("binary.msh", lambda: bytes(range(256)) * 4, "binary data"),
    ("empty.vtu", lambda: b"", "the file is empty"),
    ("truncated.vtu", lambda: b'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid"><Unstr', "truncated?"),
    ("text.xdmf", lambda: b"just words", "not XML"),
]


@pytest.mark.parametrize("name,make,cause", CASES, ids=[c[0] for c in CASES])
def test_unreadable_file_gives_one_clear_line(tmp_path, capfd, name, make, cause):
    path = _write(tmp_path, name, make())
    with pytest.raises(MeshError) as err:
        read_mesh(path)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(str(path)) and "not a valid" in msg and cause in msg
    expected = {".msh": "gmsh", ".vtu": "VTK XML", ".xdmf": "XDMF"}[path.suffix]
    assert expected in msg
    # no internal exception class names, nothing printed by the reader
    assert not re.search(r"\b\w*(Error|Exception|SystemExit)\b", msg)
    out, errout = capfd.readouterr()
    assert out == "" and errout == ""
