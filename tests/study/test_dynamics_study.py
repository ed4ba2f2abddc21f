"""Dynamics work-precision: fitted orders equal the declared ones, instabilities are data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from femkit.study import load_study, run_study, study_from_dict

ROOT = Path(__file__).resolve().parents[2]
ORDERS = {"explicit_euler": 1, "symplectic_euler": 1, "heun": 2, "midpoint": 2, "rk4": 4, "velocity_verlet": 2,
          "leapfrog": 2, "central_difference": 2, "implicit_euler": 1, "newmark": 2, "variational_symplectic": 2}

OSC = {"kind": "dynamics_work_precision",
       "scene": {"type": "harmonic_oscillator", "k": 10.0, "mass": 1.0, "amplitude": 0.1, "t_end": 2.0},
       "integrators": list(ORDERS), "dt": {"k_min": 4, "k_max": 8}, "warmup": 0}


@pytest.fixture(scope="module")
def osc(tmp_path_factory):
    return run_study(study_from_dict(OSC, name="osc"), tmp_path_factory.mktemp("osc") / "r")


@pytest.mark.parametrize("name", list(ORDERS))
def test_fitted_order_matches_declared(osc, name):
    fit = osc.fit(integrator=name)
    assert fit["declared_order"] == ORDERS[name]
    assert abs(fit["slope"] - ORDERS[name]) <= 0.15, fit
    assert fit["r2"] >= 0.999 and fit["asymptotic"]
    # the fit covers the finest dt, at least 3 of them; what was dropped is the coarse end
    dts = sorted(osc.column("dt", integrator=name))
    assert fit["dt_used"][-1] == dts[0] and len(fit["dt_used"]) >= 3
    assert all(d > max(fit["dt_used"]) for d in fit["dt_dropped"])
    assert len(fit["local_slopes"]) == len(dts) - 1


def test_error_decreases_with_dt(osc):
    for name in ORDERS:
        err = osc.column("error_max", integrator=name)
        assert np.all(np.diff(err) < 0), (name, err)


def test_symplectic_energy_bounded_explicit_euler_grows(osc):
    drift_se = osc.column("energy_drift_max", integrator="velocity_verlet")
    # velocity Verlet: bounded energy error of O(dt^2) — 4 halvings shrink it by ~256
    assert drift_se[-1] < drift_se[0] / 100
    drift_ee = osc.column("energy_drift", integrator="explicit_euler")
    assert np.all(drift_ee > 0)  # energy grows as (1 + h^2 w^2)^n


def test_unstable_run_recorded_not_raised(tmp_path):
    data = {**OSC, "integrators": ["velocity_verlet", "rk4"], "dt": {"values": [0.04, 0.02, 0.01]},
            "scene": {**OSC["scene"], "k": 1e4, "t_end": 0.4}}
    res = run_study(study_from_dict(data), tmp_path / "r")
    # omega = 100: Verlet's limit dt = 0.02, RK4's 0.0283
    vv = {r["dt"]: r["stable"] for r in res.records if r["integrator"] == "velocity_verlet"}
    rk = {r["dt"]: r["stable"] for r in res.records if r["integrator"] == "rk4"}
    assert vv == {0.04: False, 0.02: vv[0.02], 0.01: True} and rk[0.04] is False and rk[0.01] is True
    bad = [r for r in res.records if not r["stable"]]
    assert all(r["error_end"] is None and "step" in r["reason"] for r in bad)
    fit = res.fit(integrator="velocity_verlet")  # fitted over the stable runs only; the unstable listed
    assert 0.04 not in fit["dt_used"] and 0.04 in fit["unstable_dt"]
    assert "Unstable runs" in (tmp_path / "r" / "report.md").read_text()


def test_rope_against_reference_run(tmp_path):
    data = {"kind": "dynamics_work_precision", "warmup": 0,
            "scene": {"type": "rope", "n": 5, "k": 200.0, "mass": 0.1, "gravity": 9.81, "t_end": 0.5},
            "integrators": ["symplectic_euler", "velocity_verlet"], "dt": {"k_min": 7, "k_max": 10}}
    res = run_study(study_from_dict(data), tmp_path / "r")
    assert any("Reference: a rk4 run" in n for n in res.notes)
    assert abs(res.fit(integrator="velocity_verlet")["slope"] - 2) < 0.2
    assert abs(res.fit(integrator="symplectic_euler")["slope"] - 1) < 0.2


def test_bundled_dynamics_study_quick(tmp_path):
    res = load_study(ROOT / "studies" / "dynamics_work_precision.yaml", quick=True).run(tmp_path / "r")
    assert {f["integrator"] for f in res.fits} == set(ORDERS)  # every integrator, none excluded
    for f in res.fits:
        assert abs(f["slope"] - ORDERS[f["integrator"]]) <= 0.15, f
    assert len(res.figures) == 4


def test_every_integrator_has_its_own_style_and_family_line():
    from femkit.study.dynamics_work_precision.report import FAMILY_LINES, integrator_styles

    names = list(ORDERS)
    st = integrator_styles(study_from_dict({**OSC, "integrators": names}))
    assert len({s["color"] for s in st.values()}) == len(names)
    assert len({s["marker"] for s in st.values()}) == len(names)
    assert st["rk4"]["linestyle"] == FAMILY_LINES["explicit"]
    assert st["velocity_verlet"]["linestyle"] == st["variational_symplectic"]["linestyle"] == FAMILY_LINES["symplectic"]
    assert st["implicit_euler"]["linestyle"] == st["newmark"]["linestyle"] == FAMILY_LINES["implicit"]
