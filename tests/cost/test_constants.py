"""Constants are shipped, documented and overridable per machine."""

import json

import pytest

from femkit.cost import load_constants, plan_poisson
from femkit.cost.constants import ENV_VAR
from femkit.errors import InputError


def test_env_override_changes_the_plan(tmp_path, monkeypatch):
    base = plan_poisson(area=1.0, line_length=4.0, h=0.01)
    over = tmp_path / "cost.json"
    shipped = load_constants()["mesh"]["triangles_per_area_h2"]
    over.write_text(json.dumps({"mesh": {"triangles_per_area_h2": 2 * shipped}}))
    monkeypatch.setenv(ENV_VAR, str(over))
    plan = plan_poisson(area=1.0, line_length=4.0, h=0.01)
    assert 1.8 < plan.sizes["triangles"] / base.sizes["triangles"] < 2.0


def test_user_file_override(tmp_path, monkeypatch):
    (tmp_path / "femkit").mkdir()
    (tmp_path / "femkit" / "cost.json").write_text(json.dumps({"bytes": {"baseline": 1.0}}))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    monkeypatch.delenv(ENV_VAR, raising=False)
    assert load_constants()["bytes"]["baseline"] == 1.0


@pytest.mark.parametrize("content,match", [
    ({"mesh": {"triangles_per_area": 2}}, "unknown cost constant mesh.triangles_per_area;"),
    ({"bytes": {"baseline": "lots"}}, "non-negative number"),
    ({"seconds": 3}, "must be a mapping"),
], ids=["unknown-key", "string-value", "not-a-mapping"])
def test_bad_override(tmp_path, monkeypatch, content, match):
    over = tmp_path / "cost.json"
    over.write_text(json.dumps(content))
    monkeypatch.setenv(ENV_VAR, str(over))
    with pytest.raises(InputError, match=match):
        load_constants()


def test_missing_override_file(monkeypatch, tmp_path):
    monkeypatch.setenv(ENV_VAR, str(tmp_path / "nope.json"))
    with pytest.raises(InputError, match="no such file"):
        load_constants()


def test_every_solver_is_costed_or_says_it_is_not():
    """Every registered solver/preconditioner has calibrated constants, or its plan states the
    stand-in it was costed as (no silent fallback)."""
    from femkit.cost.poisson import solver_key
    from femkit.solvers.registry import PRECONDITIONERS, SOLVERS

    c = load_constants()
    for method in SOLVERS.names():
        pcs = [p for p in PRECONDITIONERS.names() if p != "amg"] if method == "pcg" else [None]
        for pc in pcs:
            key = solver_key(method, pc)
            plan = plan_poisson(area=1.0, line_length=4.0, h=0.1, refine=1, method=method,
                                preconditioner=pc)
            if key in c["bytes"]["solve_per_triangle"]:
                assert key == "direct" or key in c["iterations"], key
            else:
                assert any(f"no calibration for solver {key!r}" in a for a in plan.assumptions), key
    for key in ("cg", "pcg+amg_sa", "pcg+amg_rs", "pcg+ic0", "direct"):
        assert key in c["bytes"]["solve_per_triangle"]
