"""``element: P2`` in a Poisson case file: solve, ``femkit check`` against scikit-fem's P2, the
quadratic-cell VTU read back by meshio and by VTK's XML reader, the PNG, and one-line refusals of
unknown elements and of options P2 does not support."""

from __future__ import annotations

import json
import subprocess
import sys

import meshio
import numpy as np
import pytest

from femkit.case import case_from_dict
from femkit.case.poisson.cross_check import cross_check
from femkit.errors import CaseFileError, UnknownNameError

vtk_xml = pytest.importorskip("vtkmodules.vtkIOXML", reason="vtk (test extra) is not installed")
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

SQUARE = {
    "problem": "poisson", "name": "p2", "element": "P2",
    "mesh": {"geometry": "unit_square", "h": 0.25},
    "coefficient": 2.0,
    "source": "4*pi**2*sin(pi*x)*sin(pi*y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "x*y"}]},
    "exact": {"u": "sin(pi*x)*sin(pi*y) + x*y",
              "grad": ["pi*cos(pi*x)*sin(pi*y) + y", "pi*sin(pi*x)*cos(pi*y) + x"]},
    "solver": {"method": "direct"},
    "output": {"vtu": True, "plot": True},
}
CUBE = {**SQUARE, "mesh": {"geometry": "kuhn_cube", "h": 0.5}, "exact": None, "coefficient": 1.0,
        "source": "x + y*z", "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "x*y + z*z"}]}}


def _case(data, tmp_path=None, **changes):
    d = {k: v for k, v in {**data, **changes}.items() if v is not None}
    if tmp_path is not None:
        d["output"] = {**d["output"], "dir": str(tmp_path / "run")}
    return case_from_dict(d)


def _vtk(path):
    reader = vtk_xml.vtkXMLUnstructuredGridReader()
    events = []
    for kind in ("ErrorEvent", "WarningEvent"):
        reader.AddObserver(kind, lambda obj, event: events.append(event))
    reader.SetFileName(str(path))
    reader.Update()
    assert not events
    return reader.GetOutput()


@pytest.mark.parametrize("data, vtk_type, n_local", [(SQUARE, 22, 6), (CUBE, 24, 10)], ids=["2d", "3d"])
def test_p2_solve_writes_quadratic_cells_read_back_by_meshio_and_vtk(tmp_path, data, vtk_type, n_local):
    result = _case(data, tmp_path).run(quiet=True)
    out = tmp_path / "run"
    facts = json.loads((out / "result.json").read_text())
    mesh, u = result.mesh, result.u
    n_edges = len({tuple(sorted(p)) for c in mesh.cells.tolist() for p in
                   ([(c[0], c[1]), (c[1], c[2]), (c[0], c[2])] if mesh.dim == 2 else
                    [(c[a], c[b]) for a in range(4) for b in range(a + 1, 4)])})
    assert len(u) == mesh.n_points + n_edges
    assert facts["dofs"] < len(u)                     # the free dofs: boundary vertices and midpoints out
    assert facts["mesh"]["element"] == "P2" and facts["dofs"] + facts["n_dirichlet"] == len(u)
    m = meshio.read(out / "solution.vtu")
    assert [b.type for b in m.cells] == ["triangle6" if mesh.dim == 2 else "tetra10"]
    np.testing.assert_array_equal(m.point_data["u"], u)
    grid = _vtk(out / "solution.vtu")
    assert grid.GetNumberOfPoints() == len(u) and grid.GetNumberOfCells() == mesh.n_cells
    assert {grid.GetCellType(i) for i in range(mesh.n_cells)} == {vtk_type}
    assert grid.GetCell(0).GetNumberOfPoints() == n_local
    np.testing.assert_array_equal(vtk_to_numpy(grid.GetPointData().GetArray("u")), u)
    # every node: the vertices and the edge midpoints, where u is the field's value
    pts = vtk_to_numpy(grid.GetPoints().GetData())[:, :mesh.dim]
    if mesh.dim == 2:
        x, y = pts.T
        assert np.abs(u - (np.sin(np.pi * x) * np.sin(np.pi * y) + x * y)).max() < 5e-3
        assert facts["errors"]["L2"] < 5e-3 and (out / "solution.png").stat().st_size > 10_000
    else:  # boundary nodes carry the Dirichlet data exactly, at midpoints too
        x, y, z = pts.T
        on = (np.isclose(pts, 0) | np.isclose(pts, 1)).any(axis=1)
        np.testing.assert_allclose(u[on], (x * y + z * z)[on], atol=1e-14)


@pytest.mark.parametrize("data", [SQUARE, CUBE], ids=["2d", "3d"])
def test_femkit_check_compares_p2_with_scikit_fem(data):
    rows = {r.name: r for r in cross_check(_case(data))}
    assert all(r.passed for r in rows.values())
    assert rows["stiffness K vs scikit-fem"].difference <= 1e-12
    assert rows["load F vs scikit-fem"].difference <= 1e-12
    assert rows["solution vs scikit-fem"].difference <= 1e-10


@pytest.mark.parametrize("bad", ["P3", "p2x"])
def test_unknown_element_lists_the_valid_ones(bad):
    with pytest.raises(UnknownNameError, match=r"element: unknown element '%s'; valid elements: P1, P2" % bad):
        _case(SQUARE, element=bad)


@pytest.mark.parametrize("solver", [{"method": "fmg"}, {"method": "pcg", "preconditioner": "gmg"}],
                         ids=["fmg", "gmg"])
def test_p2_multigrid_through_the_p_level_equals_the_direct_solution(solver):
    refined = {"mesh": {"geometry": "unit_square", "h": 0.25, "refine": 1}, "output": {"vtu": False}}
    mg = _case(SQUARE, solver={**solver, "rtol": 1e-10}, **refined).run(quiet=True, write=False)
    direct = _case(SQUARE, **refined).run(quiet=True, write=False)
    assert mg.solve.converged and np.abs(mg.u - direct.u).max() < 1e-8
    assert mg.errors["L2"] == pytest.approx(direct.errors["L2"], rel=1e-6)


@pytest.mark.parametrize("change, says", [
    ({"estimator": "zz"}, "element P2: estimator 'zz' is not supported"),
    ({"quadrature": {"load": "gauss3"}}, "quadrature.load 'gauss3' (degree 2) is not exact for P2 products"),
], ids=["zz", "load-rule"])
def test_options_p2_does_not_support_are_one_line_errors(change, says):
    with pytest.raises(CaseFileError, match=says.replace("(", r"\(").replace(")", r"\)").replace("+", r"\+")):
        _case(SQUARE, **change)


def test_cli_refuses_p3_in_one_line_exit_2(tmp_path):
    path = tmp_path / "p3.json"
    path.write_text(json.dumps({**SQUARE, "element": "P3", "output": {"dir": str(tmp_path / "out")}}))
    proc = subprocess.run([sys.executable, "-m", "femkit", "solve", str(path)], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2 and proc.stderr.strip().count("\n") == 0
    assert "valid elements: P1, P2" in proc.stderr and not (tmp_path / "out").exists()


def test_p2_is_priced_before_meshing():
    """The plan of a P2 case counts P2's unknowns (a dof per vertex and per edge) and its denser
    matrix: more memory than the same case with P1, unknowns near the run's."""
    from femkit.case.poisson.cost import plan_poisson_case

    big = {"mesh": {"geometry": "unit_square", "h": 0.05}, "exact": None}
    p1 = plan_poisson_case(_case(SQUARE, element="P1", **big), measure=False)
    p2 = plan_poisson_case(_case(SQUARE, **big), measure=False)
    assert p2.sizes["unknowns"] > 3.5 * p1.sizes["unknowns"]
    assert p2.peak_bytes > p1.peak_bytes and "element P2" in p2.assumptions[0]
    result = _case(SQUARE, **big).run(quiet=True, write=False)
    assert abs(p2.sizes["unknowns"] / result.dofs - 1) < 0.25


def test_adaptive_p2_on_the_l_shape_reaches_the_optimal_rate():
    """Energy error ~ N^-1 (P2's optimal rate in 2D) under Doerfler marking at the re-entrant
    corner, where uniform P2 gains nothing over P1 (N^-1/3); effectivity in [0.5, 3] on every level."""
    from pathlib import Path

    from femkit.case import load_case

    path = Path(__file__).resolve().parents[2] / "cases" / "poisson_lshape_adaptive.yaml"
    case = load_case(path, element="P2", solver={"method": "direct", "preconditioner": "none"},
                     adaptive={"target": 1e-5, "theta": 0.5, "max_dofs": 12000, "max_time": 60})
    levels = case.run(quiet=True, write=False).adaptive["levels"]
    dofs = np.array([lv["dofs"] for lv in levels])
    err = np.array([lv["error"] for lv in levels])
    half = len(levels) // 2
    assert np.polyfit(np.log(dofs[half:]), np.log(err[half:]), 1)[0] < -0.85
    assert all(0.5 <= lv["effectivity"] <= 3.0 for lv in levels)
