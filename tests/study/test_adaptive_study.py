"""``kind: adaptive``: uniform vs adaptive on the bundled L-shape (rates) and without an exact solution."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from femkit.errors import CaseFileError, InputError
from femkit.study import load_study
from femkit.kinds import KINDS

ROOT = Path(__file__).parents[2]


@pytest.fixture(scope="module")
def lshape(tmp_path_factory):
    return load_study(ROOT / "studies" / "adaptive_lshape.yaml", quick=True).run(
        tmp_path_factory.mktemp("adaptive") / "r", progress=False)


def test_kind_is_registered():
    assert "adaptive" in KINDS.names("kind")


def test_rates_uniform_one_third_adaptive_one_half(lshape):
    """Quick size (up to 4,000 dofs): the same rates as theory (1/3 uniform, 1/2 adaptive)."""
    assert abs(-lshape.fit(run="uniform", against="dofs")["slope"] - 1 / 3) <= 0.05
    for est in ("residual", "zz"):
        assert abs(-lshape.fit(run=f"adaptive ({est})", against="dofs")["slope"] - 0.5) <= 0.05


def test_adaptive_beats_uniform_at_equal_dofs_and_estimates_are_reliable(lshape):
    recs = lshape.records
    uni = [r for r in recs if r["run"] == "uniform"]
    ada = [r for r in recs if r["run"] == "adaptive (residual)"]
    last = uni[-1]
    close = min(ada, key=lambda r: abs(r["dofs"] - last["dofs"]))
    assert close["error"] < 0.7 * last["error"]
    assert all(0.5 <= r["effectivity"] <= 3.0 for r in recs)
    assert [r["elapsed"] for r in ada] == sorted(r["elapsed"] for r in ada)


def test_report_has_the_figures_and_tables(lshape):
    out = lshape.output_dir
    for f in ("error_vs_dofs.png", "error_vs_time.png", "final_mesh.png", "effectivity.png"):
        assert (out / "figures" / f).is_file(), f
    data = json.loads((out / "results.json").read_text())
    assert {o["run"] for o in data["tables"]["outcome"]} == {"uniform", "adaptive (residual)", "adaptive (zz)"}
    assert "Fitted rates" in (out / "report.md").read_text()


def test_without_exact_solution_the_estimate_is_the_error_axis(tmp_path):
    res = load_study(ROOT / "studies" / "adaptive_inclusion.yaml", quick=True,
                     max_dofs=1500).run(tmp_path / "r", progress=False)
    assert all(r["error"] is None and r["measured"] == r["estimate"] for r in res.records)
    assert {f["error"] for f in res.fits} == {"estimate"}
    assert not (tmp_path / "r" / "figures" / "effectivity.png").exists()
    assert any("No exact solution" in n for n in res.notes)


@pytest.mark.parametrize("override, exc, text", [
    ({"theta": 1.5}, CaseFileError, "theta: must be <= 1"),
    ({"max_dofs": 0}, CaseFileError, "max_dofs: must be > 0"),
    ({"target": -1.0}, CaseFileError, "target: must be > 0"),
    ({"estimators": ["kelly"]}, InputError, "valid error estimators: residual, zz"),
    ({"solvers": [{"method": "cg"}, {"method": "direct"}]}, CaseFileError, "at most 1"),
], ids=["theta", "max_dofs", "target", "estimator", "two-solvers"])
def test_bad_adaptive_study_files(override, exc, text):
    with pytest.raises(exc, match=text):
        load_study(ROOT / "studies" / "adaptive_lshape.yaml", **override)
