"""The default ``rtol`` has one home (femkit.solvers.core.defaults.DEFAULT_RTOL): changing it there
changes it for case files, scene files and study files that do not give one."""

import pytest

import femkit.solvers.core.defaults as defaults
from femkit.case.load import case_from_dict
from femkit.study.load import study_from_dict

POISSON = {"problem": "poisson", "mesh": {"geometry": "unit_square", "h": 0.5}, "source": "1",
           "boundary": {"dirichlet": [{"tags": ["boundary"]}]}, "solver": {"method": "cg"}}
SCENE = {"problem": "mass_spring", "system": {"type": "single_spring", "k": 1.0, "m": 1.0},
         "integrator": "implicit_euler", "linear_solver": {"method": "cg"}, "dt": 0.1,
         "t_end": 1.0}


@pytest.mark.parametrize("rtol", [1e-10, 3.5e-7], ids=["shipped", "changed"])
def test_default_rtol_reaches_cases_scenes_and_studies(monkeypatch, tmp_path, rtol):
    monkeypatch.setattr(defaults, "DEFAULT_RTOL", rtol)
    assert case_from_dict(POISSON, tmp_path).solver.rtol == rtol
    assert case_from_dict(SCENE, tmp_path).solver.rtol == rtol
    exact = {**POISSON, "exact": {"u": "0"}}
    study = study_from_dict({"kind": "poisson_convergence", "problem": exact,
                             "levels": {"h0": 0.5, "count": 2}}, tmp_path)
    assert [s.rtol for s in study.solvers] == [rtol]  # the kind's default solver list
    study = study_from_dict({"kind": "stability", "cases": [{"type": "jacobi_divergence"}],
                             "solvers": [{"method": "cg"}]}, tmp_path)
    assert [s.rtol for s in study.solvers] == [rtol]
    given = case_from_dict({**POISSON, "solver": {"method": "cg", "rtol": 1e-4}}, tmp_path)
    assert given.solver.rtol == 1e-4  # a value in the file wins
