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


def test_iterations_figure_one_panel_per_case_failures_marked(tmp_path, monkeypatch):
    """All cases shared one x axis (contrast, aspect, scale, eps) and 12 colours for 20+ lines:
    'contrast: pcg+amg_sa' and 'scaled: pcg+ic0' were drawn identically; failed runs looked converged."""
    from femkit.study import figures

    seen = []
    real = figures.panels_figure
    monkeypatch.setattr(figures, "panels_figure", lambda path, panels, **kw: seen.extend(panels)
                        or real(path, panels, **kw))
    data = {"kind": "stability", "warmup": 0,
            "cases": [{"type": "poisson_contrast", "n": 8, "values": [1, 100]},
                      {"type": "poisson_anisotropic", "n": 8, "values": [1, 10]}],
            "solvers": [{"method": "cg", "rtol": 1e-8}, {"method": "cg", "rtol": 1e-8, "maxiter": 3, "label": "cg3"}]}
    res = run_study(study_from_dict(data), tmp_path / "r")
    assert [p["xlabel"] for p in seen] == ["kappa contrast", "aspect ratio"]
    for p in seen:
        assert [s["label"] for s in p["series"]] == ["cg", "cg3"]  # method names only: one style per method
        assert p["series"][0]["ok"] == [True, True] and p["series"][1]["ok"] == [False, False]
    png = (tmp_path / "r" / "figures" / "iterations_vs_parameter.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000
    assert res.figures[-1] == "figures/iterations_vs_parameter.png"
