"""Order, energy behaviour, Dahlquist stability intervals and stiff-spring growth of every integrator."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.dynamics.integrators import INTEGRATORS, StepContext, get_integrator

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared scene helpers
from _integrator_scenes import damped_particles, oscillator_map, run, unit_oscillator  # noqa: E402

# projective dynamics needs an elastic solid (tests/dynamics/test_projective.py)
ALL = [n for n in INTEGRATORS.names() if not getattr(INTEGRATORS.get(n), "solids_only", False)]


# ----------------------------------------------------------------------------- order
@pytest.mark.parametrize("name", ALL)
def test_fitted_order_matches_declared_order(name):
    """x'' = -x, x(0) = 1, v(0) = 0: error at T = 2 against (cos, -sin), slope of log-log fit."""
    integ = get_integrator(name)
    system, x0 = unit_oscillator(1.0, 1.0)
    T = 2.0
    dts = np.array([0.1, 0.05, 0.025, 0.0125])
    errs = []
    for dt in dts:
        xs, vs, _ = run(integ, system, x0, np.zeros_like(x0), dt, int(round(T / dt)))
        u, w = xs[-1, 0] - system.x0[1, 0], vs[-1, 0]
        errs.append(math.hypot(u - math.cos(T), w + math.sin(T)))
    slope = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert abs(slope - integ.order) < 0.15, (name, slope, errs)


def test_reference_oscillator_errors():
    """Unit oscillator ``x'' = -x``, x0 = 1, v0 = 0, T = 10, h = 0.1: RK4 7.3e-6, Heun 1.46e-2,
    velocity Verlet 2.8e-3 (the velocity error ``|v(10) + sin(10)|``; these are the values of the
    methods' scalar recurrences on this problem, kept here as the reference).
    """
    system, x0 = unit_oscillator(1.0, 1.0)
    for name, expected in (("rk4", 7.3e-6), ("heun", 1.46e-2), ("velocity_verlet", 2.8e-3)):
        _, vs, _ = run(get_integrator(name), system, x0, np.zeros_like(x0), 0.1, 100)
        err = abs(vs[-1, 0] + math.sin(10.0))
        assert err == pytest.approx(expected, rel=0.02, abs=0), (name, err)


# ----------------------------------------------------------------------------- energy
def _energies(name, steps=10_000, h=0.1):
    system, x0 = unit_oscillator(1.0, 1.0)
    xs, vs, _ = run(get_integrator(name), system, x0, np.zeros_like(x0), h, steps)
    u = xs[:, 0] - system.x0[1, 0]
    return 0.5 * (vs[:, 0] ** 2 + u ** 2)


def test_energy_explicit_euler_grows_exactly_as_theory():
    e = _energies("explicit_euler", steps=600)  # amplitude 1.01^300 ~ 20 << rest length
    n = np.arange(e.size)
    np.testing.assert_allclose(e / e[0], 1.01 ** n, rtol=1e-9)  # (1 + h^2 w^2)^n


def test_energy_implicit_euler_decays_exactly_as_theory():
    e = _energies("implicit_euler", steps=500)
    n = np.arange(e.size)
    np.testing.assert_allclose(e / e[0], 1.01 ** (-n), rtol=1e-9)  # (1 + h^2 w^2)^-n


@pytest.mark.parametrize("name", ["symplectic_euler", "symplectic_euler_position_first", "verlet",
                                  "velocity_verlet", "leapfrog", "central_difference"])
def test_energy_symplectic_bounded_without_drift(name):
    e = _energies(name) / 0.5
    # oscillation of the energy error is O(h) (symplectic Euler) or O(h^2) (the rest)
    bound = 0.06 if "euler" in name else 0.006
    assert np.abs(e - 1.0).max() < bound, np.abs(e - 1.0).max()
    # no secular drift: the mean over the first and the last 1000 steps agree
    assert abs(e[:1000].mean() - e[-1000:].mean()) < 1e-4


@pytest.mark.parametrize("name", ["newmark", "variational_symplectic"])
def test_energy_conserved_to_round_off(name):
    e = _energies(name, steps=500)
    # positions carry the rest offset 100 (two digits lost): round-off ~ steps * eps * 100
    assert np.abs(e / e[0] - 1.0).max() < 5e-11


# ----------------------------------------------------------------------------- Dahlquist
TABLEAU_OR_IMPLICIT = ["explicit_euler", "heun", "midpoint", "rk4", "implicit_euler", "newton",
                       "newmark", "variational_symplectic"]


def _measured_R(integ, z):
    """Amplification of one step on v' = -gamma v (damped free particles), z = -h gamma."""
    gamma = 1.0
    h = -z / gamma
    system = damped_particles(gamma)
    v = np.array([[1.0, 0.0], [0.5, -0.25]])
    ctx = StepContext()
    s = integ.step(system, integ.start(system, system.x0, v, 0.0, h, ctx), h, ctx)
    return s.v[0, 0] / v[0, 0]


@pytest.mark.parametrize("name", TABLEAU_OR_IMPLICIT)
def test_measured_amplification_equals_declared(name):
    integ = get_integrator(name)
    for z in (-0.1, -0.7, -1.9, -2.5):
        assert _measured_R(integ, z) == pytest.approx(integ.dahlquist_amplification(z).real,
                                                      rel=1e-10, abs=1e-13)


@pytest.mark.parametrize("name,edge", [("explicit_euler", -2.0), ("heun", -2.0), ("midpoint", -2.0),
                                       ("rk4", -2.785293563405)])
def test_real_stability_interval_by_bisection(name, edge):
    integ = get_integrator(name)
    lo, hi = -10.0, -0.5  # |R(lo)| > 1, |R(hi)| < 1
    assert abs(_measured_R(integ, lo)) > 1 > abs(_measured_R(integ, hi))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if abs(_measured_R(integ, mid)) > 1.0:
            lo = mid
        else:
            hi = mid
    assert hi == pytest.approx(edge, abs=1e-6)


@pytest.mark.parametrize("name", ["implicit_euler", "newton", "newmark", "variational_symplectic"])
def test_implicit_methods_stable_far_out(name):
    integ = get_integrator(name)
    assert abs(_measured_R(integ, -1e6)) <= 1.0
    assert abs(integ.dahlquist_amplification(-1e6)) <= 1.0


# ----------------------------------------------------------------------------- stiff spring
H_STIFF, OMEGA_STIFF = 1.0 / 60.0, 1000.0  # k = 1e6, m = 1: h omega = 16.7


@pytest.mark.parametrize("name,growth", [("explicit_euler", 16.7), ("symplectic_euler", 276.0),
                                         ("velocity_verlet", 276.0), ("heun", 139.0),
                                         ("midpoint", 139.0), ("rk4", 3168.0),
                                         ("implicit_euler", 0.06), ("newmark", 1.0),
                                         ("variational_symplectic", 1.0)])
def test_stiff_spring_per_step_growth(name, growth):
    """Spectral radius of each method's one-step map on the oscillator at h omega = 16.7 (the
    stiff spring k = 1e6, m = 1, h = 1/60; reference values listed in the parametrisation)."""
    A = oscillator_map(get_integrator(name), OMEGA_STIFF, H_STIFF)
    rho = np.abs(np.linalg.eigvals(A)).max()
    assert rho == pytest.approx(growth, rel=0.01)
    # theory for the explicit ones: sqrt(1 + (h w)^2) for explicit Euler, |R(i h w)| for RK
    hw = OMEGA_STIFF * H_STIFF
    if name == "explicit_euler":
        assert rho == pytest.approx(math.sqrt(1 + hw * hw), rel=1e-5)
    if name == "implicit_euler":
        assert rho == pytest.approx(1 / math.sqrt(1 + hw * hw), rel=1e-5)
