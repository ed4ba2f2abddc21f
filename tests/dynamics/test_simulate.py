"""simulate(): the SOFA analytic bound, stability warnings and clean instability errors."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.integrators import INTEGRATORS
from femkit.dynamics.simulate import StabilityWarning, simulate
from femkit.dynamics.topology import single_spring
from femkit.errors import InputError, InstabilityError, UnknownNameError

EXPLICIT = [n for n in INTEGRATORS.names() if not INTEGRATORS.get(n).implicit]
BOUNDED = ["implicit_euler", "newmark", "newton", "fast_mass_spring", "variational_symplectic"]


def test_implicit_euler_sofa_analytic_bound():
    """SOFA: K = 100, m = 10, dt = 1e-3, 2 s: |y - cos(sqrt(10) t)| <= 0.01 (true max 0.00994)."""
    traj = simulate(single_spring(k=100.0, m=10.0), "implicit_euler", 1e-3, 2.0)
    err = np.abs(traj.x[:, 1, 1] - np.cos(np.sqrt(10.0) * traj.times)).max()
    assert err <= 0.01
    assert err == pytest.approx(0.00994, abs=5e-5)
    assert traj.steps == 2000 and traj.times[-1] == pytest.approx(2.0)


def _stiff():
    s = single_spring(k=1e6, m=1.0)
    x0 = s.x0.copy()
    x0[1, 1] -= 1e-3  # stretched: a real oscillation of amplitude 1e-3
    return s, x0


@pytest.mark.parametrize("name", EXPLICIT)
def test_stiff_spring_explicit_methods_fail_cleanly(name):
    system, x0 = _stiff()
    with pytest.warns(StabilityWarning) as rec:
        with pytest.raises(InstabilityError) as info:
            simulate(system, name, 1.0 / 60.0, 2.0, x0=x0)
    msg = str(rec[0].message)
    assert "omega_max = 1000" in msg and "critical step" in msg
    err = info.value
    assert err.method == name and err.step >= 1 and err.dt == pytest.approx(1 / 60)
    bound = INTEGRATORS.get(name).stability_bound
    assert err.dt_crit == pytest.approx(bound / 1000.0, rel=1e-6)
    assert err.energy_ratio > 100 and err.time == pytest.approx(err.step / 60.0)
    part = err.partial
    assert part is not None and not part.completed
    assert np.isfinite(part.x).all() and np.isfinite(part.v).all()
    assert np.isfinite(part.energies["total"]).all()
    assert len(part.times) == err.step  # every good step up to the failure, nothing after


@pytest.mark.parametrize("name", BOUNDED)
def test_stiff_spring_implicit_methods_stay_bounded(name):
    system, x0 = _stiff()
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)
        traj = simulate(system, name, 1.0 / 60.0, 2.0, x0=x0)
    assert traj.completed and traj.steps == 120
    eq = 1.0 - 1e-5  # equilibrium y = 1 - m g / k
    assert np.abs(traj.x[:, 1, 1] - eq).max() <= 1e-3 + 1e-9
    assert traj.energies["total"].max() <= traj.energies["total"][0] + 1e-9


def test_small_dt_gives_no_warning_and_records_energies():
    system = single_spring()
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)
        traj = simulate(system, "velocity_verlet", 1e-3, 1.0, record_every=10)
    assert traj.x.shape == (101, 2, 2)
    e = traj.energies
    np.testing.assert_allclose(e["total"], e["kinetic"] + e["spring"] + e["gravity"] + e["contact"])
    assert abs(traj.energy_drift) < 1e-5
    assert traj.summary()["steps"] == 1000


def test_bad_input():
    system = single_spring()
    with pytest.raises(UnknownNameError, match="valid integrators"):
        simulate(system, "euler_forward", 1e-3, 1.0)
    with pytest.raises(InputError, match="dt"):
        simulate(system, "rk4", 0.0, 1.0)
    with pytest.raises(InputError, match="t_end"):
        simulate(system, "rk4", 1e-3, -1.0)
    with pytest.raises(InputError, match="options"):
        simulate(system, "newmark", 1e-3, 1.0, betta=0.3)


def test_stability_warning_lives_in_errors_and_is_reexported():
    import femkit.errors
    import femkit.dynamics.simulate as sim

    assert sim.StabilityWarning is femkit.errors.StabilityWarning
    assert issubclass(femkit.errors.StabilityWarning, UserWarning)
    assert not issubclass(femkit.errors.StabilityWarning, femkit.errors.FemkitError)
