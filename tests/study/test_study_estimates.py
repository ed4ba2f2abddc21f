"""Study estimates (issue 17): ``femkit study --dry-run`` sums the runs the sweep will do.

Every bundled study, full and quick, is priced at more than 0 s with its runs counted; a
measured study lands within a factor 3 of its estimate (the ratio bound is generous on
purpose: it catches a model that forgets runs, as the 4x and 0 s estimates did, not noise); a
study priced beyond the default time budget is refused unless ``--force`` is given.
"""

from pathlib import Path

import pytest
import yaml

from femkit.cost import machine_speed
from femkit.study.cost import plan_study
from femkit.study.load import load_study, study_from_dict

STUDIES = sorted((Path(__file__).parents[2] / "studies").glob("*.yaml"))


@pytest.mark.parametrize("quick", [False, True], ids=["full", "quick"])
@pytest.mark.parametrize("path", STUDIES, ids=[p.stem for p in STUDIES])
def test_every_bundled_study_is_priced_by_its_runs(path, quick):
    plan = plan_study(load_study(path, quick=quick))
    assert plan.seconds > 0.0 and plan.sizes.get("runs", 0) > 0, plan.render()
    assert all(stage.seconds >= 0.0 for stage in plan.stages)


def test_quick_is_cheaper_than_full():
    for path in STUDIES:
        full, quick = (plan_study(load_study(path, quick=q)).seconds for q in (False, True))
        assert quick < full, path.stem


@pytest.mark.parametrize("kind,data", [
    ("poisson_convergence", {
        "kind": "poisson_convergence",
        "problem": {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
                    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                    "exact": {"u": "sin(pi*x)*sin(pi*y)"}},
        "levels": {"h0": 0.05, "count": 3},
        "solvers": [{"method": "pcg", "preconditioner": "amg_sa"}, {"method": "cg"},
                    {"method": "direct"}],
        "repeats": 2}),
    ("dynamics_work_precision", {
        "kind": "dynamics_work_precision",
        "scene": {"type": "harmonic_oscillator", "k": 10, "mass": 1, "t_end": 2},
        "integrators": ["symplectic_euler", "rk4", "implicit_euler"],
        "dt": {"k_min": 5, "k_max": 9}}),
], ids=["poisson_convergence", "dynamics_work_precision"])
def test_estimate_within_a_factor_3_of_the_measured_sweep(tmp_path, kind, data):
    study = study_from_dict(data, tmp_path, name=kind)
    speed = machine_speed(statistic="median")  # this machine, its load included, now
    result = study.run(tmp_path / "out", progress=False)
    speed = (speed + machine_speed(statistic="median")) / 2.0
    estimate = plan_study(study, speed=speed).seconds
    ratio = estimate / result.elapsed
    assert 1.0 / 3.0 < ratio < 3.0, (estimate, result.elapsed, speed)


def test_study_beyond_the_default_budget_is_refused_unless_forced(tmp_path, monkeypatch, capsys):
    import femkit.cost.budget as budget
    from femkit.study.cli import cli_main

    path = STUDIES[[p.stem for p in STUDIES].index("dynamics_work_precision")]
    monkeypatch.setattr(budget, "DEFAULT_TIME_BUDGET", 1e-3)
    assert cli_main([str(path), "--quick", "-q", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exceeds the default time budget" in err[0] and "--force" in err[0]
    assert not (tmp_path / "out").exists()
    # forced: it runs (two integrators are enough to show it; the refusal above priced all)
    small = tmp_path / "small.yaml"
    small.write_text(yaml.safe_dump({**yaml.safe_load(path.read_text()),
                                     "integrators": ["explicit_euler", "rk4"]}))
    assert cli_main([str(small), "--quick", "-q", "--force", "-o", str(tmp_path / "out")]) == 0
    assert "default time budget" in capsys.readouterr().err
    assert (tmp_path / "out" / "report.html").exists()
