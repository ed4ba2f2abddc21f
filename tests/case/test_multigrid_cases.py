"""Geometric multigrid from case files: `refine: k` carries its hierarchy to gmg and fmg."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import femkit
from femkit.errors import HierarchyError


def _case(base_case, solver, refine, **mesh):
    d = dict(base_case)
    d["mesh"] = {"geometry": "l_shape", "h": 0.5, "refine": refine, **mesh}
    d["source"] = "1"
    d["exact"] = None
    d.pop("exact")
    d["solver"] = solver
    return d


@pytest.mark.parametrize("solver", [
    pytest.param({"method": "fmg"}, id="fmg"),
    pytest.param({"method": "pcg", "preconditioner": "gmg", "rtol": 1e-10}, id="pcg-gmg")])
def test_multigrid_case_matches_the_direct_solution(solver, base_case, write_case, tmp_path):
    # inhomogeneous Dirichlet data: fmg gets the coarse levels' own systems from the pipeline
    d = _case(base_case, solver, 4)
    d["boundary"] = {"dirichlet": [{"tags": ["boundary"], "value": "x + 2*y"}]}
    mg = femkit.load_case(write_case(d)).run(output_dir=tmp_path / "mg", quiet=True)
    d["solver"] = {"method": "direct"}
    ref = femkit.load_case(write_case(d, "direct.yaml")).run(write=False, quiet=True)
    assert mg.converged
    diff = abs(mg.u - ref.u).max()
    info = json.loads((tmp_path / "mg" / "result.json").read_text())["solver"]["multigrid"]
    assert info["levels"] == 5 and info["coarse"] == "galerkin"
    if solver["method"] == "fmg":
        # stopped at the discretisation error (not at rtol): far from round-off, well below
        # the O(h^2) discretisation error of this mesh (h ~ 0.03)
        assert diff < 1e-4
        assert info["stopped_by"] == "discretisation-error estimate"
        assert info["cycles_per_level"][-1] <= 3
        assert info["algebraic_error_estimate"] <= 0.1 * info["discretisation_error_estimate"]
    else:
        assert diff < 1e-8


@pytest.mark.parametrize("solver", [{"method": "fmg"}, {"method": "pcg", "preconditioner": "gmg"}],
                         ids=["fmg", "gmg"])
def test_multigrid_without_refinement_is_one_line_error_naming_amg_rs(solver, base_case, write_case):
    path = write_case(_case(base_case, solver, 0))
    with pytest.raises(HierarchyError, match="amg_rs"):
        femkit.load_case(path)
    proc = subprocess.run([sys.executable, "-m", "femkit.cli", "solve", str(path)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "amg_rs" in proc.stderr
    assert "refine" in proc.stderr


def test_multigrid_with_adaptive_refinement_is_refused(base_case, write_case):
    d = _case(base_case, {"method": "fmg"}, 2)
    d["adaptive"] = {"target": 0.01}
    with pytest.raises(HierarchyError, match="adaptive refinement.*amg_rs"):
        femkit.load_case(write_case(d))


def test_fmg_on_a_pure_neumann_case_matches_amg():
    from pathlib import Path

    path = Path(__file__).parents[2] / "cases" / "poisson_neumann.yaml"
    mesh = {"h": 0.25, "refine": 3}
    fmg = femkit.load_case(path, mesh=mesh, solver={"method": "fmg", "preconditioner": "none"})
    amg = femkit.load_case(path, mesh=mesh)
    r_fmg, r_amg = fmg.run(write=False, quiet=True), amg.run(write=False, quiet=True)
    assert r_fmg.converged and r_fmg.solve.info["stopped_by"] == "discretisation-error estimate"
    # stopped at the discretisation error: the same error as the rtol 1e-10 solve, to 1%
    assert r_fmg.errors["L2"] == pytest.approx(r_amg.errors["L2"], rel=1e-2)
