"""The bundled cloth work-precision study, run small: records, Pareto fronts, figure, references."""

from __future__ import annotations

from pathlib import Path

import pytest

from femkit.errors import CaseFileError
from femkit.study import load_study, run_study, study_from_dict

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "studies" / "cloth_work_precision.yaml"


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    return run_study(load_study(STUDY, quick=True), tmp_path_factory.mktemp("cloth") / "r")


def test_quick_study_measures_every_method(quick):
    labels = [r["label"] for r in quick.records]
    assert labels == ["fast mass-spring 1 it", "fast mass-spring 5 it",
                      "Chebyshev fast mass-spring 5 it", "Baraff-Witkin", "Newton 1 it", "Newton 3 it"]
    for r in quick.records:
        assert r["scene"] == "hanging_cloth" and r["nodes"] == 49 and not r["failed"]
        assert r["time_per_frame"] > 0 and r["solve_error"] > 0 and r["trajectory_error"] > 0
    by = {r["label"]: r for r in quick.records}
    # more work, smaller solve error; Newton 3 it is the implicit Euler step to the reference's
    # own tolerance (converged local/global, tol 1e-10)
    assert by["fast mass-spring 5 it"]["solve_error"] < by["fast mass-spring 1 it"]["solve_error"]
    assert by["Chebyshev fast mass-spring 5 it"]["solve_error"] < by["fast mass-spring 5 it"]["solve_error"]
    assert by["Newton 3 it"]["solve_error"] < 1e-6 < 1e-3 * by["fast mass-spring 1 it"]["solve_error"]


def test_pareto_fronts_and_outputs(quick):
    fronts = [r for r in quick.records if r["pareto_solve"]]
    assert fronts                                           # the most accurate run is always on it
    best = min(quick.records, key=lambda r: r["solve_error"])
    assert best["pareto_solve"]
    fastest = min(quick.records, key=lambda r: r["time_per_frame"])
    assert fastest["pareto_solve"] and fastest["pareto_trajectory"]
    out = quick.output_dir
    assert (out / "figures" / "hanging_cloth_work_precision.png").stat().st_size > 10_000
    assert (out / "references.csv").is_file() and (out / "runs.csv").is_file()
    ref = quick.tables["references"][0]
    # implicit Euler's own discretisation error bounds every trajectory error from below (roughly)
    assert min(r["trajectory_error"] for r in quick.records) >= 0.5 * ref["implicit_euler_trajectory_error"]


def test_non_cloth_scene_is_refused(tmp_path):
    data = {"kind": "cloth_work_precision", "scenes": [str(ROOT / "cases/scenes/rope_pendulum.yaml")]}
    with pytest.raises(CaseFileError, match="not a cloth scene"):
        study_from_dict(data, base_dir=tmp_path)
    data = {"kind": "cloth_work_precision", "scenes": [str(ROOT / "cases/scenes/hanging_cloth.yaml")],
            "methods": [{"family": "verlet"}]}
    with pytest.raises(CaseFileError, match="methods"):
        study_from_dict(data, base_dir=tmp_path)


def _small(methods, linear_solver=None):
    data = {"kind": "cloth_work_precision", "scenes": [str(ROOT / "cases/scenes/hanging_cloth.yaml")],
            "system_overrides": {"nx": 7, "ny": 7}, "frames": 4, "methods": methods,
            "reference": {"substeps": 8}}
    if linear_solver is not None:
        data["linear_solver"] = linear_solver
    return data


@pytest.mark.cholmod  # the study-wide solver here is cholesky (optional CHOLMOD)
def test_a_method_family_takes_its_own_linear_solver_spec(tmp_path):
    """methods[i].linear_solver is validated like every solver spec, recorded per run and used:
    the same steps with an explicit SuperLU (direct) as with the study's Cholesky."""
    bad = _small([{"family": "newton", "iterations": [2], "linear_solver": {"method": "direct", "rtl": 1}}])
    with pytest.raises(CaseFileError, match=r"methods\[0\]\.linear_solver\.rtl"):
        study_from_dict(bad, base_dir=tmp_path)
    res = run_study(study_from_dict(_small([
        {"family": "newton", "iterations": [2]},
        {"family": "newton", "iterations": [2], "linear_solver": {"method": "direct"}}],
        linear_solver={"method": "cholesky"}),
        base_dir=tmp_path), tmp_path / "r")
    a, b = res.records
    assert a["linear_solver"] == "" and b["linear_solver"] == "direct"
    assert abs(a["solve_error"] - b["solve_error"]) <= 1e-8 * a["solve_error"]


@pytest.mark.pardiso
def test_the_study_linear_solver_options_reach_the_steps(tmp_path, monkeypatch):
    """The study's linear_solver is passed whole (options included), not just its method name."""
    import femkit.solvers.pardiso as pardiso

    calls = []
    original = pardiso.factorize_pardiso
    monkeypatch.setattr(pardiso, "factorize_pardiso",
                        lambda *a, **k: calls.append(1) or original(*a, **k))
    run_study(study_from_dict(_small([{"family": "baraff_witkin"}],
                                     {"method": "cholesky", "options": {"engine": "pardiso"}}),
                              base_dir=tmp_path), tmp_path / "r")
    assert calls  # the PARDISO engine factorised the Baraff-Witkin steps
