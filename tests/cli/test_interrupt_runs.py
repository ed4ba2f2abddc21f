"""A stop request inside a run answers at once (issue 17: the cloth study's Liu reference ignored
SIGINT for 657 s, the stress study waited 37 s for its current run): during a Poisson case's
assembly, during its long iterative solve, and inside a study's run. Each ``femkit`` subprocess
signals itself a set time after it has entered the work under test (by its own clock, so the
signal lands inside that work however the machine schedules the test) and the test measures
signal-to-exit time (the target is 1 s; the assertion allows 3 s on an idle machine, scaled by
the load per core when other processes share it: a stop that waited for the work to end would
take the rest of the run, tens of seconds), the exit code, the one line saying what was kept,
and the kept output."""

import json
import signal
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helper
from _signals import signal_inside, slack  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
SIGNALS = pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                                  ids=["SIGINT", "SIGTERM"])


def _poisson(tmp_path, refine: int, rtol: float, method: str = "cg") -> Path:
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump({
        "problem": "poisson",
        "mesh": {"geometry": "unit_square", "h": 0.02, "refine": refine},
        "source": "1",
        "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
        "solver": {"method": method, "rtol": rtol, "maxiter": 10_000_000},
        "output": {"dir": "out", "vtu": False}}))
    return case


@SIGNALS
def test_signal_during_assembly_stops_at_once_and_writes_nothing(tmp_path, sig, code):
    # 6M triangles: the compiled row-wise assembly takes ~2 s (at 1.5M it ended before the signal
    # on a quiet machine: 'after the assembly stage')
    case = _poisson(tmp_path, refine=5, rtol=1e-8)
    rc, elapsed, err = signal_inside("femkit.fem.poisson:PoissonProblem.assemble_matrices",
                                     ["solve", str(case), "--quiet"], sig, cwd=tmp_path,
                                     settle=0.1)
    assert rc == code, err
    assert elapsed < slack(), elapsed
    assert f"interrupted by {sig.name} during assembly; nothing written" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


@SIGNALS
def test_signal_during_a_long_solve_writes_the_last_iterate_marked(tmp_path, sig, code):
    # Jacobi to 1e-12 on 12k unknowns: minutes of cheap iterations, then a small estimate
    case = _poisson(tmp_path, refine=1, rtol=1e-12, method="jacobi")
    rc, elapsed, err = signal_inside("femkit.interrupt:stopping_callback",
                                     ["solve", str(case), "--quiet"], sig, cwd=tmp_path)
    assert rc == code, err
    assert elapsed < slack(), elapsed
    assert f"interrupted by {sig.name}" in err and "Traceback" not in err
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["interrupted"] is True
    assert result["solver"]["converged"] is False and result["solver"]["iterations"] > 0


@SIGNALS
def test_signal_during_the_errors_stops_the_solution_writer_and_writes_nothing(tmp_path, sig, code):
    """After the solve, solution.vtu is being written by a writer thread beside the errors: a
    stop there ends the run at once, waits for the writer and removes what it staged (nothing
    is left beside the output directory either)."""
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump({
        "problem": "poisson",
        "mesh": {"geometry": "unit_square", "h": 0.02, "refine": 4},
        "source": "2 * pi**2 * sin(pi * x) * sin(pi * y)",
        "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
        "exact": {"u": "sin(pi * x) * sin(pi * y)",
                  "grad": ["pi * cos(pi * x) * sin(pi * y)", "pi * sin(pi * x) * cos(pi * y)"]},
        "solver": {"method": "fmg"},
        "output": {"dir": "out", "vtu": True}}))
    rc, elapsed, err = signal_inside("femkit.fem.poisson:PoissonProblem.errors",
                                     ["solve", str(case), "--quiet"], sig, cwd=tmp_path,
                                     settle=0.05)
    assert rc == code, err
    assert elapsed < slack(), elapsed
    assert f"interrupted by {sig.name}" in err and "nothing written" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.yaml"]


def _earlier_report(out: Path) -> dict:
    out.mkdir()
    files = {"results.json": '{"earlier": true}\n', "report.md": "# the earlier report\n"}
    for name, text in files.items():
        (out / name).write_text(text)
    return files


def _check_study_stopped(rc, elapsed, err, sig, code, out, files):
    assert rc == code, err
    assert elapsed < slack(), elapsed
    lines = err.strip().splitlines()
    assert f"interrupted by {sig.name} during" in lines[-1], err
    assert "earlier report" in lines[-1] and "Traceback" not in err
    assert {p.name: p.read_text() for p in out.iterdir()} == files  # kept as it was


@SIGNALS
def test_signal_inside_the_cloth_studys_reference_run(tmp_path, sig, code):
    # the Liu-style reference: local/global iterations run to a tolerance never met in time
    study = tmp_path / "cloth.yaml"
    study.write_text(yaml.safe_dump({
        "kind": "cloth_work_precision",
        "scenes": [str(REPO / "cases" / "scenes" / "hanging_cloth.yaml")],
        "system_overrides": {"nx": 30, "ny": 30}, "frames": 50,
        "linear_solver": {"method": "direct"},  # the default install's solver: the stop is tested
        "methods": [{"family": "fast_mass_spring", "iterations": [1]}],
        "reference": {"tol": 1e-15, "solve": "local_global", "trajectory": "rk4", "substeps": 2}}))
    out = tmp_path / "report"
    files = _earlier_report(out)
    rc, elapsed, err = signal_inside(
        "femkit.dynamics.integrators.fast_mass_spring:FastMassSpring.step",
        ["study", str(study), "--output", str(out), "--quiet"], sig, cwd=tmp_path)
    _check_study_stopped(rc, elapsed, err, sig, code, out, files)


@SIGNALS
def test_signal_inside_a_poisson_studys_solve(tmp_path, sig, code):
    study = tmp_path / "conv.yaml"
    study.write_text(yaml.safe_dump({
        "kind": "poisson_convergence",
        "problem": {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
                    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
                    "exact": {"u": "sin(pi*x)*sin(pi*y)"}},
        "levels": {"h0": 0.02, "count": 3},
        "solvers": [{"method": "cg", "rtol": 1e-15, "maxiter": 1000000}], "repeats": 1}))
    out = tmp_path / "report"
    files = _earlier_report(out)
    rc, elapsed, err = signal_inside("femkit.study.poisson_convergence.run:_assemble", ["study", str(study), "--output",
                                     str(out), "--quiet"], sig, cwd=tmp_path)
    _check_study_stopped(rc, elapsed, err, sig, code, out, files)
