"""``kind: element_work_precision`` beyond the unit square: the unit cube (P2 more accurate per
unknown), the L-shape (uniform P2 gains no rate, adaptive series do), Cook's membrane (a solid
base case: P1 locks, P2 does not), and the crossover on curves with a known answer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from femkit.errors import CaseFileError, UnknownNameError
from femkit.study import run_study, study_from_dict
from femkit.study.element_work_precision.report import crossover_line
from femkit.study.element_work_precision.run import crossover

ROOT = Path(__file__).resolve().parents[2]
CUBE = {
    "kind": "element_work_precision",
    "problem": {"mesh": {"geometry": "kuhn_cube"}, "source": "3*pi**2*sin(pi*x)*sin(pi*y)*sin(pi*z)",
                "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                "exact": {"u": "sin(pi*x)*sin(pi*y)*sin(pi*z)",
                          "grad": ["pi*cos(pi*x)*sin(pi*y)*sin(pi*z)", "pi*sin(pi*x)*cos(pi*y)*sin(pi*z)",
                                   "pi*sin(pi*x)*sin(pi*y)*cos(pi*z)"]}},
    "levels": {"h0": 0.5, "count": 3}, "counts": [3, 2],
    "solver": {"method": "direct"}, "repeats": 1, "warmup": 0,
}
LSHAPE = {
    "kind": "element_work_precision", "base_case": str(ROOT / "cases" / "poisson_lshape.yaml"),
    "levels": {"h0": 0.5, "count": 4}, "counts": [4, 3],
    "adaptive": {"elements": ["P1", "P2"], "max_dofs": 800},
    "solver": {"method": "direct"}, "repeats": 1, "warmup": 0,
}
COOK = {
    "kind": "element_work_precision", "base_case": str(ROOT / "cases" / "solid_cook_membrane.yaml"),
    "levels": {"h0": 8.0, "count": 2}, "counts": [2, 2],
    "reference": {"point": [48.0, 60.0], "component": 1, "value": 19.428},
    "repeats": 1, "warmup": 0,
}


def _run(data, name, tmp_path_factory, write: bool = False):
    """The study's run; the report (figures: seconds of matplotlib) only when ``write``."""
    return run_study(study_from_dict(data, name=name), tmp_path_factory.mktemp(name) / "report",
                     write=write)


def _rows(result, series):
    return [r for r in result.records if r["element"] == series]


def test_cube_p2_is_more_accurate_at_equal_unknowns(tmp_path_factory):
    """Tetrahedra: P2 on level k has P1 level k+1's unknowns and a smaller L2 and H1 error."""
    res = _run(CUBE, "cube", tmp_path_factory)
    p1, p2 = _rows(res, "P1"), _rows(res, "P2")
    assert [r["dofs"] for r in p2] == [r["dofs"] for r in p1[1:]]
    for a, b in zip(p1[1:], p2):
        assert b["L2"] < a["L2"] / 2 and b["H1_semi"] < a["H1_semi"], (a, b)
    assert {(c["low"], c["high"], c["norm"]) for c in res.tables["crossover"]} == {
        ("P1", "P2", "L2"), ("P1", "P2", "H1_semi")}


def test_lshape_uniform_p2_gains_no_rate_adaptive_does(tmp_path_factory):
    """r^(2/3): uniform P1 and P2 both converge like h^(2/3) = dofs^(-1/3) in H1 (Strang & Fix);
    the adaptive loop restores dofs^(-p/2): P2 adaptive beats both the uniform rates by far."""
    res = _run(LSHAPE, "lshape", tmp_path_factory, write=True)
    rate = {(f["element"], f["norm"]): f["rate_vs_dofs"] for f in res.fits}
    assert -0.42 < rate["P1", "H1_semi"] < -0.25 and -0.42 < rate["P2", "H1_semi"] < -0.25, rate
    assert abs(rate["P2", "H1_semi"] - rate["P1", "H1_semi"]) < 0.1, rate     # measured -0.28, -0.31
    assert rate["P2 adaptive", "H1_semi"] < -0.8 and rate["P1 adaptive", "H1_semi"] < -0.4, rate
    assert all(r["L2"] is None and r["H1_semi"] > 0 for r in _rows(res, "P2 adaptive"))
    pairs = {(c["low"], c["high"]) for c in res.tables["crossover"] if c["norm"] == "H1_semi"}
    assert pairs == {("P1", "P2"), ("P1", "P1 adaptive"), ("P2", "P2 adaptive"), ("P1 adaptive", "P2 adaptive")}
    assert "P2 adaptive" in (res.output_dir / "report.md").read_text()


def test_cook_p1_locks_p2_does_not(tmp_path_factory):
    """nu = 0.4999: at equal unknowns P2's corner error is a fraction of locking P1's."""
    res = _run(COOK, "cook", tmp_path_factory)
    p1, p2 = _rows(res, "P1"), _rows(res, "P2")
    assert p2[0]["dofs"] == p1[1]["dofs"]
    assert p1[1]["corner"] > 0.25 and p2[0]["corner"] < 0.05, (p1, p2)
    assert p2[1]["corner"] < p2[0]["corner"]
    (c,) = res.tables["crossover"]
    assert c["norm"] == "corner" and "more accurate than every P1 run" in crossover_line(c)


def _power_law(series, coef, rate, errors):
    """Runs whose cost is ``coef * error^-rate`` (straight lines in log-log)."""
    return [{"element": series, "t": coef * e ** -rate, "L2": e} for e in errors]


def test_crossover_of_power_laws_is_where_they_meet():
    """P1 t = 1e-4 e^-2, P2 t = 1e-2 e^-1: equal at e = 1e-2, P2 cheaper below."""
    recs = (_power_law("P1", 1e-4, 2, np.geomspace(1e-1, 1e-4, 5))
            + _power_law("P2", 1e-2, 1, np.geomspace(2e-1, 3e-5, 4)))
    c = crossover(recs, "P1", "P2", "L2")
    assert c["error"] == pytest.approx(1e-2, rel=0.03) and not c["everywhere"]
    assert c["range"] == pytest.approx([1e-4, 1e-1])
    assert "below 1.0" in crossover_line(c) or "below 9.9" in crossover_line(c)


def test_no_crossover_in_range_is_said():
    """P2 dearer at every common error: no crossover, and the sentence says so."""
    recs = (_power_law("P1", 1e-2, 1, np.geomspace(1e-1, 1e-3, 4))
            + _power_law("P2", 1e-1, 1, np.geomspace(1e-1, 1e-3, 3)))
    c = crossover(recs, "P1", "P2", "L2")
    assert c["error"] is None and not c["everywhere"]
    assert "not cheaper" in crossover_line(c) and "no crossover" in crossover_line(c)
    far = _power_law("P1", 1.0, 1, [1e-1, 1e-2]) + _power_law("P2", 1.0, 1, [1e-4, 1e-5])
    c = crossover(far, "P1", "P2", "L2")
    assert c["range"] is None and c["apart"]["high_errors"] == pytest.approx([1e-5, 1e-4])
    assert "more accurate than every P1 run" in crossover_line(c)


@pytest.mark.parametrize("base, change, error, says", [
    (LSHAPE, {"adaptive": {"elements": ["P3"], "max_dofs": 100}}, UnknownNameError, "adaptive.elements[0]"),
    (LSHAPE, {"reference": {"point": [0, 0], "component": 0, "value": 1}}, CaseFileError, "only for a solid"),
    (LSHAPE, {"case_overrides": {"mesh": {"h": 0.1}}}, CaseFileError, "case_overrides: only for a solid"),
    (COOK, {"reference": None}, CaseFileError, "a solid base case needs 'reference'"),
    (COOK, {"adaptive": {"elements": ["P1"], "max_dofs": 100}}, CaseFileError, "Poisson cases only"),
])
def test_bad_input_is_one_line(base, change, error, says):
    data = {k: v for k, v in {**base, **change}.items() if v is not None}
    with pytest.raises(error) as err:
        study_from_dict(data, name="bad")
    assert says in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("reference, says", [
    ({"point": [47.0, 60.0], "component": 1, "value": 1.0}, "reference.point [47.0, 60.0] is not a node"),
    ({"point": [48.0, 60.0], "component": 2, "value": 1.0}, "valid: 0 (x), 1 (y)"),
])
def test_a_bad_reference_is_refused_before_any_solve(reference, says, tmp_path):
    study = study_from_dict({**COOK, "reference": reference}, name="bad")
    with pytest.raises(CaseFileError) as err:
        run_study(study, tmp_path / "out")
    assert says in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "out").exists()
