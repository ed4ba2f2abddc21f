"""Pure-Neumann case files: the bundled case converges, options are checked, results say how.

``cases/poisson_neumann.yaml``: u = cos(pi x) cos(pi y), zero flux, ``nullspace: mean_zero``.
"""

import json
from pathlib import Path

import numpy as np
import pytest

import femkit
from femkit.case.poisson.cross_check import cross_check
from femkit.errors import CaseFileError, SingularSystemError

CASE = Path(__file__).parents[2] / "cases" / "poisson_neumann.yaml"


@pytest.mark.parametrize("solver", [{"method": "direct", "preconditioner": "none"}, {"method": "pcg", "preconditioner": "amg"}],
                         ids=["direct-bordered", "pcg-amg-pinned"])
def test_bundled_case_converges_at_rates_2_and_1_on_gmsh_refinements(solver):
    h, l2, h1 = [], [], []
    for level in range(4):  # one gmsh mesh, h = 0.25, and 3 red refinements
        r = femkit.load_case(CASE, mesh={"h": 0.25, "refine": level}, solver=solver).run(
            write=False, quiet=True)
        assert r.converged
        h.append(r.quality["h_max"])
        l2.append(r.errors["L2"])
        h1.append(r.errors["H1_semi"])
    rate_l2 = np.polyfit(np.log(h), np.log(l2), 1)[0]
    rate_h1 = np.polyfit(np.log(h), np.log(h1), 1)[0]
    assert abs(rate_l2 - 2) < 0.1 and abs(rate_h1 - 1) < 0.1, (rate_l2, rate_h1)
    assert np.all(np.diff(l2) < 0)


def test_pin_and_mean_zero_give_the_same_solution_modulo_the_constant():
    runs = {mode: femkit.load_case(CASE, mesh={"h": 0.2}, solver={"method": "direct", "preconditioner": "none"},
                                   boundary={"nullspace": mode}).run(write=False, quiet=True)
            for mode in ("mean_zero", "pin")}
    d = runs["pin"].u - runs["mean_zero"].u
    assert np.ptp(d) < 1e-10
    # pin uses the exact value at node 0 when exact is given
    x0, y0 = runs["pin"].mesh.points[0]
    assert runs["pin"].u[0] == pytest.approx(np.cos(np.pi * x0) * np.cos(np.pi * y0), abs=1e-14)
    for key in ("L2", "H1_semi", "max_nodal"):
        assert runs["pin"].errors[key] == pytest.approx(runs["mean_zero"].errors[key], rel=1e-8)
    assert runs["mean_zero"].dofs == runs["mean_zero"].mesh.n_points + 1  # bordered
    assert runs["pin"].dofs == runs["pin"].mesh.n_points - 1


def test_result_json_records_how_the_constant_was_fixed(tmp_path):
    femkit.load_case(CASE, mesh={"h": 0.25}).run(output_dir=tmp_path / "out", quiet=True)
    facts = json.loads((tmp_path / "out" / "result.json").read_text())
    ns = facts["nullspace"]
    assert ns["mode"] == "mean_zero" and "pinned" in ns["how"]
    assert ns["flux_integral"] == 0 and 0 <= ns["relative_imbalance"] < ns["rtol"] == 1e-3
    assert facts["n_dirichlet"] == 0


def test_cases_with_dirichlet_data_keep_nullspace_null(tmp_path):
    r = femkit.load_case(CASE.parent / "poisson_unit_square.yaml", mesh={"h": 0.25}).run(
        write=False, quiet=True)
    assert r.to_dict()["nullspace"] is None


def test_nullspace_keys_with_dirichlet_data_are_refused(write_case, base_case):
    base_case["boundary"]["nullspace"] = "pin"
    with pytest.raises(CaseFileError, match=r"boundary.nullspace: only for pure-Neumann"):
        femkit.load_case(write_case(base_case))


def test_unknown_nullspace_mode_lists_the_valid_ones():
    with pytest.raises(CaseFileError, match="valid values: mean_zero, pin, error"):
        femkit.load_case(CASE, boundary={"nullspace": "mean"})


def test_incompatible_source_raises_and_nullspace_error_refuses():
    with pytest.raises(SingularSystemError, match="int f dx = 1 and int h ds = 0"):
        femkit.load_case(CASE, mesh={"h": 0.25}, source=1).run(write=False)
    with pytest.raises(SingularSystemError, match="no Dirichlet condition"):
        femkit.load_case(CASE, mesh={"h": 0.25}, boundary={"nullspace": "error"}).run(write=False)


@pytest.mark.parametrize("method", ["direct", "pcg"])
def test_cross_check_against_scikit_fem_and_pyamg_at_mean_zero(method):
    solver = {"method": method, "preconditioner": "amg" if method == "pcg" else "none"}
    case = femkit.load_case(CASE, mesh={"h": 0.2}, solver=solver)
    rows = cross_check(case)
    assert all(r.passed for r in rows), rows
    assert "mean zero" in rows[2].name
