"""simulate()'s instability detection: no false alarm below the critical step, a clean error above it.

Scenes: a single spring with gravity (small oscillation about equilibrium) and a small flat cloth
with gravity (at rest, E_0 = 0, sagging under its own weight). The critical step is
``stability_bound / omega_max`` with ``omega_max`` estimated at the initial state.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
import yaml

from femkit.dynamics.forces import Gravity, ViscousDamping
from femkit.dynamics.integrators import INTEGRATORS
from femkit.dynamics.simulate import StabilityWarning, energy_scale, simulate
from femkit.dynamics.stability import critical_dt, estimate_omega_max
from femkit.dynamics.topology import cloth_grid, single_spring
from femkit.errors import InstabilityError

#: explicit methods with a true h*omega limit on the undamped oscillator
OSCILLATOR_STABLE = ["symplectic_euler", "symplectic_euler_position_first", "verlet",
                     "velocity_verlet", "leapfrog", "central_difference", "rk4"]
#: explicit methods stable only on [-2, 0] of the real axis (never on the undamped oscillator)
REAL_AXIS_ONLY = ["explicit_euler", "heun", "midpoint"]
STEPS = 2000


def spring(shift=0.0):
    """k = 100, m = 1, g = 1: oscillation of amplitude m g / k = 0.01 about equilibrium."""
    s = single_spring(k=100.0, m=1.0, gravity=1.0)
    return s, s.x0 + np.array([0.0, shift])


def cloth(shift=0.0, gravity=9.81):
    """5 x 5 horizontal cloth at z = 0 (E_0 = 0), pinned at two corners, sagging under gravity."""
    forces = [Gravity(gravity)] if gravity else []
    s = cloth_grid(5, 5, 1.0, 1.0, k_structural=500.0, k_shear=200.0, k_bending=50.0, mass=0.01,
                   plane="xy", forces=forces)
    return s, s.x0 + np.array([0.0, 0.0, shift])


SCENES = {"spring": spring, "cloth": cloth}


def dt_crit(system, x0, name):
    return critical_dt(estimate_omega_max(system, x0), INTEGRATORS.get(name).stability_bound)


def run(scene, name, factor, shift=0.0, steps=STEPS):
    system, x0 = SCENES[scene](shift)
    dt = factor * dt_crit(system, x0, name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StabilityWarning)
        return simulate(system, name, dt, steps * dt, x0=x0, record_every=50)


def assert_clean_error(err, name, steps):
    assert err.method == name
    assert 1 <= err.step <= steps
    assert err.time == pytest.approx(err.step * err.dt)
    assert err.energy_ratio > 1e-3 and err.reason
    part = err.partial
    assert not part.completed and part.steps == err.step - 1
    for arr in (part.x, part.v, part.energies["total"], part.times):
        assert np.isfinite(arr).all()


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("name", OSCILLATOR_STABLE)
def test_below_critical_step_no_false_alarm(scene, name):
    traj = run(scene, name, 0.9)
    assert traj.completed and traj.steps == STEPS
    assert traj.dt_exceeds_critical is False
    assert np.isfinite(traj.x).all()


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("name", OSCILLATOR_STABLE)
def test_above_critical_step_raises_cleanly(scene, name):
    with pytest.raises(InstabilityError) as info:
        run(scene, name, 1.1)
    err = info.value
    assert_clean_error(err, name, STEPS)
    assert err.dt > err.dt_crit
    if scene == "spring":  # the unstable mode is excited: |R| > 1 per step is caught early
        assert err.step < 100


@pytest.mark.parametrize("name", OSCILLATOR_STABLE + REAL_AXIS_ONLY)
@pytest.mark.parametrize("factor", [0.9, 1.1], ids=["dt0.9crit", "dt1.1crit"])
def test_verdict_invariant_to_gravity_origin(name, factor):
    """The spring with gravity, and the same spring lifted by 1000: same verdict, same step."""
    outcomes = []
    for shift in (0.0, 1000.0):
        try:
            traj = run("spring", name, factor, shift=shift, steps=500)
            outcomes.append(("stable", traj.steps, traj.energy_scale))
        except InstabilityError as err:
            outcomes.append(("unstable", err.step, err.partial.energy_scale))
    assert outcomes[0][0] == outcomes[1][0]
    assert abs(outcomes[0][1] - outcomes[1][1]) <= 10  # at most one check apart (round-off)
    assert outcomes[1][2] == pytest.approx(outcomes[0][2], rel=1e-9)


@pytest.mark.parametrize("scene", list(SCENES))
def test_energy_scale_is_origin_free_and_positive_at_rest(scene):
    system, x0 = SCENES[scene](0.0)
    _, x_up = SCENES[scene](1000.0)
    v0 = np.zeros_like(x0)
    s0, s_up = energy_scale(system, x0, v0), energy_scale(system, x_up, v0)
    assert s0 > 0.0 and s_up == pytest.approx(s0, rel=1e-12)
    if scene == "cloth":  # at rest, unstretched, at z = 0: E_0 = 0 and S = m_free g L
        assert system.energies(x0, v0)["total"] == 0.0
        m_free = system.mass[~system.pinned].sum()
        assert s0 == pytest.approx(m_free * 9.81 * np.sqrt(2.0), rel=1e-12)


def test_pre_stretched_stiff_spring_scale_is_its_spring_energy():
    """No gravity: S = 1/2 k s^2 exactly (the old force-times-diameter term gave k s L >> that)."""
    s = single_spring(k=1e4, m=1.0, gravity=None)
    x0 = s.x0.copy()
    x0[1, 1] -= 0.05
    assert energy_scale(s, x0, np.zeros_like(x0)) == pytest.approx(0.5 * 1e4 * 0.05 ** 2, rel=1e-12)


@pytest.mark.parametrize("gravity", [9.81, 0.0], ids=["gravity", "no-gravity"])
def test_cloth_at_rest_no_false_alarm(gravity):
    system, x0 = cloth(0.0, gravity)
    assert system.energies(x0, np.zeros_like(x0))["total"] == 0.0
    dt = 0.5 * dt_crit(system, x0, "velocity_verlet")
    traj = simulate(system, "velocity_verlet", dt, STEPS * dt, x0=x0, record_every=100)
    assert traj.completed and traj.steps == STEPS
    if gravity:
        assert traj.x[-1][:, 2].min() < -0.01  # it did sag
    else:
        np.testing.assert_array_equal(traj.x[-1], x0)


def overdamped_spring(gamma=4.0):
    """k = m = 1 with viscous damping gamma = 4: eigenvalues -2 +- sqrt(3), all on the real axis."""
    return single_spring(k=1.0, m=1.0, gravity=None, forces=[ViscousDamping(gamma)])


@pytest.mark.parametrize("name", REAL_AXIS_ONLY)
@pytest.mark.parametrize("factor", [0.9, 1.1], ids=["h0.9", "h1.1"])
def test_real_axis_methods_on_overdamped_spring(name, factor):
    """Stable iff h |lambda_min| <= 2 (real interval [-2, 0]); lambda_min = -(2 + sqrt 3)."""
    system = overdamped_spring()
    x0 = system.x0.copy()
    x0[1, 1] -= 0.1
    h = factor * 2.0 / (2.0 + np.sqrt(3.0))
    if factor < 1.0:
        traj = simulate(system, name, h, STEPS * h, x0=x0, record_every=100)
        assert traj.completed and traj.steps == STEPS
    else:
        with pytest.raises(InstabilityError) as info:
            simulate(system, name, h, STEPS * h, x0=x0, record_every=100)
        assert_clean_error(info.value, name, STEPS)
        assert info.value.step < 500


@pytest.mark.parametrize("name,h_omega", [("explicit_euler", 0.1), ("heun", 0.5), ("midpoint", 0.5)])
def test_real_axis_methods_never_stable_on_undamped_oscillator(name, h_omega):
    """Far below dt_crit = 2/omega the energy still grows geometrically ((1 + (h w)^2) per step for
    Euler, 1 + (h w)^4/4 for RK2): no warning, but the run is stopped by the growth rule."""
    system, x0 = spring()
    dt = h_omega / 10.0  # omega = 10
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)
        with pytest.raises(InstabilityError) as info:
            simulate(system, name, dt, 20000 * dt, x0=x0, record_every=100)
    err = info.value
    assert_clean_error(err, name, 20000)
    assert err.dt < err.dt_crit
    assert "geometrically" in err.reason


def test_stiff_spring_instability_reported_in_scene_even_when_run_too_short(tmp_path):
    """One step of symplectic Euler at h omega = 16.7: no growth seen yet, but the verdict says so."""
    from femkit.cli import main

    scene = {"problem": "mass_spring", "name": "short_stiff",
             "system": {"type": "single_spring", "k": 1.0e6, "m": 1.0},
             "forces": {"gravity": 10.0}, "integrator": {"method": "symplectic_euler"},
             "dt": "1/60", "t_end": "1/60", "stability": {"check_every": 1},
             "output": {"every": 1, "vtu": False}}
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(scene))
    out = tmp_path / "out"
    assert main(["solve", str(path), "-o", str(out), "-q"]) == 0
    st = json.loads((out / "result.json").read_text())["stability"]
    assert st["verdict"] == "stable" and st["dt_exceeds_critical"] is True
    assert st["dt_crit"] == pytest.approx(2e-3, rel=1e-6)

    scene["integrator"] = {"method": "implicit_euler"}
    path.write_text(yaml.safe_dump(scene))
    assert main(["solve", str(path), "-o", str(out), "-q"]) == 0
    st = json.loads((out / "result.json").read_text())["stability"]
    assert st["verdict"] == "stable" and st["dt_exceeds_critical"] is False
