"""Review defect: two-point fits reported R² = 1 and 'asymptotic'."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.study import run_study, study_from_dict
from femkit.study.fit import fit_asymptotic, fit_rate

SMOOTH = {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
          "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "sin(pi*x)*sin(pi*y)"}]},
          "exact": {"u": "sin(pi*x)*sin(pi*y)",
                    "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}}


def test_two_point_fit_has_no_r2():
    """Two points always lie on a line: R² = 1 says nothing and must not be reported as 1."""
    fit = fit_rate([0.1, 0.05], [1e-2, 2.4e-3])
    assert fit.slope == pytest.approx(np.log(1e-2 / 2.4e-3) / np.log(2))
    assert np.isnan(fit.r2) and np.isnan(fit.slope_stderr)
    assert fit.as_dict()["r2"] is None


def test_two_point_asymptotic_fit_is_not_called_asymptotic():
    a = fit_asymptotic([0.1, 0.05], [1e-2, 2.5e-3])
    assert a.fit.slope == pytest.approx(2.0) and a.asymptotic is False


def test_two_dt_dynamics_study_flags_fit_and_renders(tmp_path):
    data = {"kind": "dynamics_work_precision", "warmup": 0,
            "scene": {"type": "harmonic_oscillator", "t_end": 1}, "integrators": ["rk4"],
            "dt": {"values": [0.125, 0.0625]}}
    res = run_study(study_from_dict(data), tmp_path / "r")
    f = res.fit(integrator="rk4")
    assert f["r2"] is None and f["asymptotic"] is False
    md = (tmp_path / "r" / "report.md").read_text()
    assert "| rk4 | 4 |" in md and "| 1 |" not in md.split("## Fitted orders")[1].split("##")[0]


def test_two_level_poisson_rate_table_shows_no_r2(tmp_path):
    data = {"kind": "poisson_convergence", "warmup": 0, "problem": SMOOTH,
            "levels": {"h0": 0.25, "count": 2}, "solvers": [{"method": "direct"}]}
    res = run_study(study_from_dict(data), tmp_path / "r")
    assert all(f["r2"] is None and f["n"] == 2 for f in res.fits)
    table = (tmp_path / "r" / "report.md").read_text().split("## Fitted convergence rates")[1].split("##")[0]
    row = [ln for ln in table.splitlines() if ln.startswith("| direct | barycentric | L2")][0]
    assert row.split("|")[6].strip() == "-"  # R² column


def test_dynamics_stability_map_draws_no_limit_for_never_stable_methods(tmp_path, monkeypatch):
    """Explicit Euler / Heun / midpoint got a 'theoretical limit' bar at 2 on an undamped scene."""
    from femkit.study import figures

    seen = {}
    real = figures.stability_map_figure

    def spy(path, rows, **kw):
        seen.update({r["method"]: r["bound"] for r in rows})
        return real(path, rows, **kw)

    monkeypatch.setattr(figures, "stability_map_figure", spy)
    data = {"kind": "dynamics_work_precision", "warmup": 0, "scene": {"type": "harmonic_oscillator", "t_end": 1},
            "integrators": ["explicit_euler", "heun", "velocity_verlet", "rk4"], "dt": {"k_min": 5, "k_max": 6}}
    run_study(study_from_dict(data), tmp_path / "r")
    assert seen["explicit_euler"] is None and seen["heun"] is None
    assert seen["velocity_verlet"] == 2.0 and seen["rk4"] == pytest.approx(2 * np.sqrt(2))
