"""Review defect: the dynamics reference run's own error was neither estimated nor stated."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.study import run_study, study_from_dict

SMOOTH = {"exact": "sin(pi*x)*sin(pi*y)", "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
          "grad_exact": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}


def test_reference_run_states_its_own_error(tmp_path):
    data = {"kind": "dynamics_work_precision", "warmup": 0,
            "scene": {"type": "rope", "n": 4, "k": 100.0, "gravity": 9.81, "t_end": 0.5},
            "integrators": ["symplectic_euler"], "dt": {"k_min": 5, "k_max": 7}}
    res = run_study(study_from_dict(data), tmp_path / "r")
    ref = res.tables["reference"][0]
    # RK4 at dt/16 of the finest step: its error is many orders below the runs' errors
    assert 0 < ref["error_estimate"] < 1e-3 * min(r["error_max"] for r in res.records)
    assert any("error estimate" in n for n in res.notes)


def test_unconverged_reference_is_said_and_limits_the_fit(tmp_path):
    """A reference as coarse as the runs: the report must say so instead of fitting against it."""
    data = {"kind": "dynamics_work_precision", "warmup": 0,
            "scene": {"type": "rope", "n": 4, "k": 100.0, "gravity": 9.81, "t_end": 0.5},
            "integrators": ["rk4"], "dt": {"k_min": 5, "k_max": 7},
            "reference": {"integrator": "symplectic_euler", "dt": 2.0 ** -8}}
    res = run_study(study_from_dict(data), tmp_path / "r")
    assert res.tables["reference"][0]["error_estimate"] > 1e-4
    assert any("not converged" in n for n in res.notes)
    assert res.fits == []  # every rk4 error lies below 10x the reference's own error


@pytest.mark.parametrize("name, every", [("rk4", 64), ("rk4", 63), ("velocity_verlet", 64), ("symplectic_euler", 64)],
                         ids=["rk4-even", "rk4-odd", "verlet", "symplectic-euler"])
def test_reference_error_estimate_matches_analytic_error(name, every):
    """The Richardson estimate of the reference's own error against the oscillator's exact solution."""
    from femkit.study.dynamics_work_precision.run import _reference_run, build_scene

    scene = {"type": "harmonic_oscillator", "k": 10.0, "mass": 1.0, "amplitude": 0.1, "rest": 1.0, "n": 8,
             "gravity": 0.0, "t_end": 4.0}
    from femkit.study.dynamics_work_precision.spec import DynamicsScene

    system, x0, v0, exact = build_scene(DynamicsScene(**scene))
    traj, est = _reference_run(system, name, 0.0625, every, 4.0, x0, v0)
    d = (traj.x - exact(np.arange(65) * 0.0625))[:, ~system.pinned]
    true = np.sqrt((d.reshape(len(d), -1) ** 2).sum(axis=1)).max()
    assert est == pytest.approx(true, rel=0.05)
