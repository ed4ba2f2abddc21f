"""Mesh files through ``femkit solve`` (issue 17): a triangle listed twice is refused naming it,
a node no triangle uses is dropped with a printed note (as docs/case-files.md says), and a
mesh-file error names the file once. Bad input: exit 2, one line, nothing written."""

import json

import numpy as np
import pytest
import yaml

from femkit.cli import main
from femkit.mesh import Mesh, write_mesh
from femkit.mesh.structured import structured_mesh


def _case(tmp_path, mesh: Mesh):
    write_mesh(tmp_path / "m.msh", mesh, msh_version="2.2")
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump({
        "problem": "poisson", "mesh": {"file": "m.msh"}, "source": "1",
        "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
        "solver": {"method": "direct"}, "output": {"dir": "out", "vtu": False}}))
    return case


def _one_error_line(capsys, tmp_path, case, before) -> str:
    assert main(["solve", str(case)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert set(tmp_path.iterdir()) == before  # nothing written
    return err[0]


def test_a_triangle_listed_twice_in_a_file_is_refused_naming_it(tmp_path, capsys):
    m = structured_mesh(4, 4)
    case = _case(tmp_path, Mesh(points=m.points, triangles=np.vstack([m.cells, m.cells[5]])))
    line = _one_error_line(capsys, tmp_path, case, set(tmp_path.iterdir()))
    assert line.startswith("femkit: error: mesh.file ")
    assert "share their node set" in line and "element ids 5 = 32" in line


def test_an_unused_node_in_a_file_is_dropped_with_a_note(tmp_path, capsys):
    m = structured_mesh(4, 4)
    pts = np.vstack([m.points, [[3.0, 3.0]]])  # node 25, used by no triangle
    case = _case(tmp_path, Mesh(points=pts, triangles=m.cells))
    assert main(["solve", str(case)]) == 0
    out = capsys.readouterr().out
    assert "note      mesh.file: 1 node used by no triangle dropped (node ids 25)" in out
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["mesh"]["n_points"] == 25 and result["mesh"]["area"] == pytest.approx(1.0)
    assert main(["solve", str(case), "--quiet", "--output", str(tmp_path / "q")]) == 0
    assert capsys.readouterr().out == ""


@pytest.mark.parametrize("text", ["garbage\n", "$MeshFormat\n2.2 0 8\n"], ids=["garbage", "truncated"])
def test_a_mesh_file_error_names_the_path_once(tmp_path, capsys, text):
    case = _case(tmp_path, structured_mesh(2, 2))
    (tmp_path / "m.msh").write_text(text)
    line = _one_error_line(capsys, tmp_path, case, set(tmp_path.iterdir()))
    path = str((tmp_path / "m.msh").resolve())
    assert line.count(path) == 1, line
