"""``element: P2`` in ``problem: solid`` case files: the bundled Cook's membrane end to end (its
quadratic-triangle frames read back by meshio and by VTK's own XML reader), a P2 tetrahedral body
through a time integrator (quadratic tetrahedra in the frames, HRZ masses), and bad input (an
unknown element, an integrator that cannot take P2: one line, exit 2, nothing written)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.cli import main

CASES = Path(__file__).parents[2] / "cases"

#: a small P2 dynamic case: a 1 x 0.25 x 0.25 beam, clamped, swinging under gravity
DYNAMIC = {
    "problem": "solid", "name": "p2beam",
    "mesh": {"geometry": "beam", "h": 0.25, "params": {"length": 1.0, "width": 0.25, "height": 0.25}},
    "element": "P2",
    "material": {"model": "stable_neo_hookean", "E": 1.0e5, "nu": 0.3, "density": 100.0},
    "boundaries": [{"tag": "clamped", "type": "fixed"}],
    "gravity": [0.0, 0.0, -9.81],
    "integrator": "newton", "dt": 0.01, "t_end": 0.03,
    "output": {"png": False, "every": 1},
}


def _write(tmp_path, data, name="case.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _vtk_read(path: Path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    types = np.array([grid.GetCellType(i) for i in range(grid.GetNumberOfCells())])
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    return grid.GetNumberOfPoints(), types, u


def test_bundled_cook_membrane_p2_writes_quadratic_triangles(tmp_path):
    import meshio

    out = tmp_path / "cook"
    assert main(["solve", str(CASES / "solid_cook_membrane.yaml"), "--output", str(out),
                 "--quiet"]) == 0
    res = json.loads((out / "result.json").read_text())
    assert res["mesh"]["element"] == "P2" and res["converged"]
    frame = out / "frames" / "frame_00001.vtu"
    m = meshio.read(frame)
    assert list(m.cells_dict) == ["triangle6"] and len(m.points) == res["mesh"]["points"]
    corner = np.flatnonzero(np.all(np.isclose(m.points[:, :2], [48.0, 60.0]), axis=1))
    uy = float(m.point_data["displacement"][corner[0], 1])
    assert abs(uy / 19.428 - 1.0) < 0.03                                  # docs/solids.md
    assert np.all(np.isfinite(m.cell_data["von_mises"][0]))
    n, types, u = _vtk_read(frame)
    assert n == len(m.points) and set(types.tolist()) == {22}
    np.testing.assert_array_equal(u, m.point_data["displacement"])
    # the edge midpoints move with their edges: straight-sided rest cells, smooth field
    mids = m.cells_dict["triangle6"][:, 3]
    ends = m.cells_dict["triangle6"][:, :2]
    disp = m.point_data["displacement"]
    gap = np.abs(disp[mids] - 0.5 * (disp[ends[:, 0]] + disp[ends[:, 1]])).max()
    assert 0.0 < gap < 0.05 * np.abs(disp).max()


def test_p2_tetrahedra_through_a_time_integrator(tmp_path):
    out = tmp_path / "beam"
    assert main(["solve", str(_write(tmp_path, DYNAMIC)), "--output", str(out), "--quiet"]) == 0
    res = json.loads((out / "result.json").read_text())
    assert res["mesh"]["element"] == "P2" and res["converged"] and res["steps"] == 3
    n, types, u = _vtk_read(out / "frames" / "frame_00003.vtu")
    assert n == res["mesh"]["points"] and set(types.tolist()) == {24}
    assert u[:, 2].min() < 0.0 and np.abs(u[:, :2]).max() < np.abs(u[:, 2]).max()  # it sags
    e = res["energies"]
    assert e[-1]["kinetic"] > 0.0 and e[-1]["gravity"] < 0.0


@pytest.mark.parametrize("change, needle", [
    ({"element": "P3"}, "element: 'P3' is not allowed; valid values: P1, P2"),
    ({"element": "p2x"}, "element: 'p2x' is not allowed; valid values: P1, P2"),
    ({"integrator": "projective"}, "element: P2 is not supported by the integrator 'projective'"),
], ids=["P3", "p2x", "projective"])
def test_bad_element_input_is_one_line_exit_2(change, needle, tmp_path, capsys):
    data = copy.deepcopy(DYNAMIC)
    data.update(change)
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and needle in err, err
    assert not out.exists()
