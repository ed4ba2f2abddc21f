"""``kind: element_work_precision``: P1 and P2 on nested meshes, rates against unknowns, the
crossover, the report, and its bad input."""

from __future__ import annotations

import pytest

from femkit.errors import CaseFileError, UnknownNameError
from femkit.study import run_study, study_from_dict
from femkit.study.element_work_precision.run import crossover

STUDY = {
    "kind": "element_work_precision",
    "problem": {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
                "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                "exact": {"u": "sin(pi*x)*sin(pi*y)",
                          "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}},
    "levels": {"h0": 0.25, "count": 4},
    "counts": [4, 3],
    "solver": {"method": "direct"},
    "repeats": 1, "warmup": 0,
}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    return run_study(study_from_dict(STUDY, name="elements"), tmp_path_factory.mktemp("el") / "report")


@pytest.mark.parametrize("element, norm, theory", [("P1", "L2", -1.0), ("P1", "H1_semi", -0.5),
                                                  ("P2", "L2", -1.5), ("P2", "H1_semi", -1.0)])
def test_rates_against_unknowns(result, element, norm, theory):
    """2D: error ~ N^(-(p+1)/2) in L2 and N^(-p/2) in H1 (h ~ N^(-1/2))."""
    fit = next(f for f in result.fits if f["element"] == element and f["norm"] == norm)
    assert abs(fit["rate_vs_dofs"] - theory) < 0.12, fit["rate_vs_dofs"]


def test_p2_is_more_accurate_per_unknown_and_the_crossover_is_stated(result):
    recs = result.records
    p1 = [r for r in recs if r["element"] == "P1"]
    p2 = [r for r in recs if r["element"] == "P2"]
    assert [r["dofs"] for r in p2][:2] == [r["dofs"] for r in p1][1:3]   # P2 level k = P1 level k+1's unknowns
    assert all(b["L2"] < a["L2"] / 3 for a, b in zip(p1[1:], p2))
    cross = {(c["norm"], c["cost"]) for c in result.tables["crossover"]}
    assert cross == {("L2", "t"), ("H1_semi", "t")}
    assert (result.output_dir / "figures" / "error_vs_time.png").is_file()
    assert "cheaper" in (result.output_dir / "report.md").read_text()


def test_crossover_by_unknowns_is_everywhere_for_p2():
    """Against unknowns P2 is cheaper at every error of a smooth problem (its curve lies below)."""
    recs = [{"element": "P1", "dofs": n, "L2": 1.0 / n} for n in (10, 40, 160)]
    recs += [{"element": "P2", "dofs": n, "L2": 0.5 / n ** 1.5} for n in (10, 40, 160)]
    c = crossover(recs, "P1", "P2", "L2", cost="dofs")
    assert c["everywhere"] and c["range"] is not None
    assert crossover(recs, "P2", "P1", "L2", cost="dofs")["error"] is None   # the other way: never


@pytest.mark.parametrize("change, error, says", [
    ({"elements": ["P1", "P3"]}, UnknownNameError, "elements[1]: unknown element 'P3'; valid elements: P1, P2"),
    ({"elements": ["P1", "P1"]}, CaseFileError, "each element once"),
    ({"counts": [3]}, CaseFileError, "counts"),
])
def test_bad_input_is_one_line(change, error, says):
    with pytest.raises(error) as err:
        study_from_dict({**STUDY, **change}, name="bad")
    assert says in str(err.value) and "\n" not in str(err.value)
