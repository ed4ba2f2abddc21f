"""Error estimates in every Poisson result and the ``adaptive:`` case key, through ``femkit solve``."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
import yaml

from femkit.cli import main

ROOT = Path(__file__).parents[2]

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the CLI tests' small case
from test_cli import SMALL as _SMALL  # noqa: E402

SMALL = {**_SMALL, "mesh": {"geometry": "unit_square", "h": 0.1}, "solver": {"method": "direct"},
         "output": {"dir": "out", "vtu": False}}

LSHAPE = yaml.safe_load((ROOT / "cases" / "poisson_lshape_adaptive.yaml").read_text())


def _run(tmp_path, data, capsys, *extra):
    p = tmp_path / "case.yaml"
    p.write_text(yaml.safe_dump(data))
    code = main(["solve", str(p), *extra])
    out = capsys.readouterr()
    return code, out, tmp_path / "out" / "result.json"


@pytest.mark.parametrize("estimator", ["residual", "zz"])
def test_result_json_has_the_estimate_and_its_effectivity(tmp_path, capsys, estimator):
    code, out, path = _run(tmp_path, {**SMALL, "estimator": estimator}, capsys)
    assert code == 0
    res = json.loads(path.read_text())
    est = res["error_estimate"]
    assert est["estimator"] == estimator
    # the estimate is checked against the true energy error, computed independently
    assert 0.5 <= est["energy"] / est["true_energy_error"] <= 3.0
    assert res["effectivity"] == pytest.approx(est["energy"] / est["true_energy_error"])
    assert est["true_energy_error"] == pytest.approx(res["errors"]["H1_semi"], rel=1e-12)   # kappa = 1
    assert list(est["per_region"]) == ["domain"]
    assert f"({estimator} estimator, effectivity" in out.out
    assert res["adaptive"] is None


def test_without_exact_solution_the_estimate_is_still_given(tmp_path, capsys):
    data = yaml.safe_load((ROOT / "cases" / "poisson_high_contrast.yaml").read_text())
    data["mesh"]["h"] = 0.1
    data["output"] = {"dir": "out", "vtu": False, "plot": True}
    code, out, path = _run(tmp_path, data, capsys)
    assert code == 0
    res = json.loads(path.read_text())
    assert res["errors"] is None and res["effectivity"] is None
    regions = res["error_estimate"]["per_region"]
    assert set(regions) == {"inclusion", "matrix"}
    assert (sum(v ** 2 for v in regions.values())) ** 0.5 == pytest.approx(res["error_estimate"]["energy"])
    assert "estimate  energy-norm error ~" in out.out
    from PIL import Image

    with Image.open(tmp_path / "out" / "solution.png") as im:     # solution + indicator panels
        assert im.size[0] > 1.8 * im.size[1]


def test_adaptive_case_meets_its_target(tmp_path, capsys):
    data = {**LSHAPE, "adaptive": {"target": 4e-2, "theta": 0.5}, "output": {"dir": "out", "vtu": False}}
    code, out, path = _run(tmp_path, data, capsys)
    assert code == 0
    a = json.loads(path.read_text())["adaptive"]
    assert a["target_met"] and a["stop_reason"] == "target"
    assert a["levels"][-1]["estimate"] <= 4e-2 < a["levels"][-2]["estimate"]
    assert [lv["dofs"] for lv in a["levels"]] == sorted(lv["dofs"] for lv in a["levels"])
    assert "target met" in out.out


def test_adaptive_budget_before_target_exits_zero_and_says_so(tmp_path, capsys):
    data = {**LSHAPE, "adaptive": {"target": 1e-6, "max_dofs": 300}, "output": {"dir": "out", "vtu": False}}
    code, out, path = _run(tmp_path, data, capsys)
    assert code == 0
    a = json.loads(path.read_text())["adaptive"]
    assert a["target_met"] is False and a["stop_reason"] == "max_dofs"
    assert all(lv["n_nodes"] <= 300 for lv in a["levels"])
    assert "target NOT met: stopped by max_dofs" in out.out


@pytest.mark.parametrize("adaptive, piece", [
    ({"target": 1e-2, "theta": 0}, "adaptive.theta: must be > 0"),
    ({"target": 1e-2, "theta": 1.5}, "adaptive.theta: must be <= 1"),
    ({"target": 0}, "adaptive.target: must be > 0"),
    ({"target": -1e-3}, "adaptive.target: must be > 0"),
    ({"max_dofs": 0}, "adaptive.max_dofs: must be > 0"),
    ({"max_dofs": 2.5}, "adaptive.max_dofs: expected an integer"),
    ({"max_time": -1}, "adaptive.max_time: must be > 0"),
    ({"target": 1e-2, "max_levels": 0}, "adaptive.max_levels: must be > 0"),
    ({"theta": 0.5}, "adaptive: give at least one of target, max_dofs, max_time"),
], ids=["theta0", "theta1.5", "target0", "target<0", "dofs0", "dofs2.5", "time<0", "levels0", "no-stop"])
def test_bad_adaptive_settings_are_one_line_errors_exit_2(tmp_path, capsys, adaptive, piece):
    code, out, path = _run(tmp_path, {**LSHAPE, "adaptive": adaptive, "output": {"dir": "out"}}, capsys)
    assert code == 2
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("femkit: error: ") and piece in lines[0], out.err
    assert not path.parent.exists()


def test_unknown_estimator_lists_the_valid_ones(tmp_path, capsys):
    code, out, _ = _run(tmp_path, {**SMALL, "estimator": "kelly"}, capsys)
    assert code == 2 and "valid error estimators: residual, zz" in out.err
