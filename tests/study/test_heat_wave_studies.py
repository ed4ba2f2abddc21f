"""The heat work-precision and wave energy studies (quick settings): the explicit barrier is in
the records where theory puts it, the energy-conserving schemes' drift is round-off, implicit
Euler's falls with dt, and both reports are written."""

from __future__ import annotations

from pathlib import Path

from femkit.study import load_study

ROOT = Path(__file__).resolve().parents[2]


def test_heat_work_precision_shows_the_explicit_barrier(tmp_path):
    study = load_study(ROOT / "studies" / "heat_work_precision.yaml", quick=True,
                       dt=[0.005, 0.0025, 0.00125], h=[0.1])
    res = study.run(tmp_path / "r", progress=False)
    recs = res.records
    assert len(recs) == 3 * len(study.spec.schemes)
    for r in recs:
        if r["explicit"]:  # stable exactly below the critical step computed on the mesh
            assert r["stable"] == (r["dt"] <= r["dt_critical"]), r
        else:
            assert r["stable"] and r["dt_critical"] is None
    ie = [r["error"] for r in recs if r["integrator"] == "implicit_euler"]
    assert ie[0] > 1.8 * ie[1] > 1.8 ** 2 * ie[2] * 0.95  # first order in dt
    assert (tmp_path / "r" / "figures" / "heat_work_precision.png").exists()


def test_wave_energy_drift(tmp_path):
    study = load_study(ROOT / "studies" / "wave_energy.yaml", quick=True,
                       schemes=["newmark", "central_difference", "implicit_euler"])
    res = study.run(tmp_path / "r", progress=False)
    by = {}
    for r in res.records:
        by.setdefault(r["integrator"], []).append(r)
    assert all(r["drift"] < 1e-11 for r in by["newmark"])
    ie = [r["drift"] for r in by["implicit_euler"]]
    assert ie[0] > ie[1] > ie[2] > 0.0 and all(r["final_ratio"] < 1.0 for r in by["implicit_euler"])
    cd = [r["drift"] for r in by["central_difference"] if r["stable"]]
    assert 3.0 < cd[-2] / cd[-1] < 5.0  # second order: the drift falls as dt^2
    assert (tmp_path / "r" / "figures" / "energy_drift.png").exists()


def test_stiff_heat_study_only_the_implicit_schemes_take_long_steps(tmp_path):
    """The stiff variant at h = 1/64: explicit Euler's critical
    step is below every dt given, so each of its runs is unstable, while the implicit schemes
    are stable at every dt and Crank-Nicolson / BDF2 at the larger dt already meet the error
    of the smaller one within 2x (the time error is no longer what limits them)."""
    study = load_study(ROOT / "studies" / "heat_work_precision_stiff.yaml", quick=True,
                       dt=[0.0003125, 0.000078125], h=[0.015625])
    recs = study.run(tmp_path / "r", progress=False).records
    for r in recs:
        if r["explicit"]:
            assert r["dt_critical"] < 0.000078125 and not r["stable"], r
        else:
            assert r["stable"], r
    for name in ("crank_nicolson", "bdf2"):
        big, small = (r["error"] for r in recs if r["integrator"] == name)
        assert big < 2.0 * small, (name, big, small)
