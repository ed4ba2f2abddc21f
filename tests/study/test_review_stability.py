"""Review defects: stability study files with bad names or overrides ran instead of failing."""

from __future__ import annotations

import pytest

from femkit.errors import CaseFileError, UnknownNameError
from femkit.study import run_study, study_from_dict

SMOOTH = {"exact": "sin(pi*x)*sin(pi*y)", "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
          "grad_exact": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}


def test_stability_unknown_solver_is_an_input_error(tmp_path):
    """A misspelled solver name produced a table of FAIL cells instead of an error."""
    data = {"kind": "stability", "warmup": 0, "cases": [{"type": "poisson_contrast", "n": 8, "values": [1]}],
            "solvers": [{"method": "pcgg"}]}
    with pytest.raises(UnknownNameError, match="pcgg"):
        run_study(study_from_dict(data), tmp_path / "r")
    data["solvers"] = [{"method": "pcg", "preconditioner": "amgg"}]
    with pytest.raises(UnknownNameError, match="amgg"):
        run_study(study_from_dict(data), tmp_path / "r")
    assert not (tmp_path / "r").exists()


def test_stability_override_of_unknown_case_is_an_error(tmp_path):
    """A typo in case_overrides silently ran the case at full size (1e6 unknowns for `fine`)."""
    data = {"kind": "stability", "warmup": 0, "cases": [{"type": "jacobi_divergence", "name": "jac"}],
            "case_overrides": {"jacc": {"n": 4}}}
    with pytest.raises(CaseFileError, match=r"case_overrides\.jacc.*jac"):
        run_study(study_from_dict(data), tmp_path / "r")


def test_stability_values_must_be_numbers():
    with pytest.raises(CaseFileError, match=r"cases\[0\]\.values"):
        study_from_dict({"kind": "stability", "cases": [{"type": "poisson_contrast", "values": ["a"]}]})
