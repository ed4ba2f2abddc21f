"""Fast mass-spring's global solves are counted (issue 17: ``0 solves`` though it does one per
local/global iteration): ``iterations`` per step by the method's definition (Liu et al. 2013,
no tolerance: every iteration runs), in result.json and in the printed summary."""

import json

import pytest
import yaml

from femkit.cli import main


@pytest.mark.parametrize("iterations, steps", [(10, 6), (3, 4)], ids=["10-it", "3-it"])
@pytest.mark.parametrize("method", [pytest.param("cholesky", marks=pytest.mark.cholmod), "direct"])
def test_fast_mass_spring_counts_one_solve_per_iteration(tmp_path, capsys, iterations, steps, method):
    case = tmp_path / "scene.yaml"
    case.write_text(yaml.safe_dump({
        "problem": "mass_spring",
        "system": {"type": "cloth", "nx": 5, "ny": 5, "width": 1.0, "height": 1.0,
                   "k_structural": 100.0, "k_shear": 20.0, "k_bending": 5.0, "total_mass": 0.1,
                   "pinned": "top_corners"},
        "forces": {"gravity": 9.81},
        "integrator": {"method": "fast_mass_spring", "options": {"iterations": iterations}},
        "linear_solver": {"method": method},
        "dt": 0.01, "t_end": 0.01 * steps,
        "output": {"dir": "out", "vtu": False}}))
    assert main(["solve", str(case)]) == 0
    solves = iterations * steps
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["linear_solver"]["linear_solves"] == solves
    assert result["linear_solver"]["factorizations"] == 1
    assert f": {solves} solves," in capsys.readouterr().out
