"""Every integrator reproduces its hand-written scalar recurrence (SOFA ODE-solver test style).

Scene (SOFA): node 0 fixed at y = 2, spring rest length 1 to node 1 starting at y = 1 with
v = 0, gravity. The free node moves along y only; the scalar force is
``F(y) = K (1 - y) - m g`` and Rayleigh damping adds ``-(r_M m + r_K K) v``. The recurrences
below are written from SOFA's ODE solver documentation (EulerImplicitSolver,
NewmarkImplicitSolver, VariationalSymplecticSolver, RungeKutta4Solver, CentralDifferenceSolver)
and Schlögl's lecture notes (explicit and symplectic Euler, Verlet),
independently of femkit's vector code.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.dynamics.integrators import get_integrator

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared scene helpers
from _integrator_scenes import run, sofa_spring  # noqa: E402

K, M, G, H, STEPS = 100.0, 10.0, 10.0, 0.01, 300


def F(y):
    return K * (1.0 - y) - M * G


def acc(y):
    return F(y) / M


def rec_explicit_euler(h, n, **_):
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        y, v = y + h * v, v + h * acc(y)
        out.append(y)
    return out


def rec_symplectic_euler(h, n, **_):
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        v = v + h * acc(y)
        y = y + h * v
        out.append(y)
    return out


def rec_symplectic_euler_position_first(h, n, **_):
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        y = y + h * v
        v = v + h * acc(y)
        out.append(y)
    return out


def rec_heun(h, n, **_):
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        a0 = acc(y)
        vt, yt = v + h * a0, y + h * v
        y, v = y + h * (v + vt) / 2.0, v + h * (a0 + acc(yt)) / 2.0
        out.append(y)
    return out


def rec_midpoint(h, n, **_):  # SOFA RungeKutta2
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        yh, vh = y + 0.5 * h * v, v + 0.5 * h * acc(y)
        y, v = y + h * vh, v + h * acc(yh)
        out.append(y)
    return out


def rec_rk4(h, n, **_):  # SOFA RungeKutta4
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        k1v, k1a = v, acc(y)
        k2x, k2v = y + k1v * h / 2, v + k1a * h / 2
        k2a = acc(k2x)
        k3x, k3v = y + k2v * h / 2, v + k2a * h / 2
        k3a = acc(k3x)
        k4x, k4v = y + k3v * h, v + k3a * h
        k4a = acc(k4x)
        y = y + k1v * h / 6 + k2v * h / 3 + k3v * h / 3 + k4v * h / 6
        v = v + k1a * h / 6 + k2a * h / 3 + k3a * h / 3 + k4a * h / 6
        out.append(y)
    return out


def rec_verlet(h, n, **_):  # position Stormer
    y_prev, y = 1.0, 1.0 + 0.5 * h * h * acc(1.0)
    out = [y_prev, y]
    for _ in range(n - 1):
        y_prev, y = y, 2.0 * y - y_prev + h * h * acc(y)
        out.append(y)
    return out


def rec_velocity_verlet(h, n, **_):
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        a0 = acc(y)
        y = y + h * v + 0.5 * h * h * a0
        v = v + 0.5 * h * (a0 + acc(y))
        out.append(y)
    return out


def rec_leapfrog(h, n, **_):
    y, vh, out = 1.0, 0.5 * h * acc(1.0), [1.0]
    for _ in range(n):
        y = y + h * vh
        vh = vh + h * acc(y)
        out.append(y)
    return out


def rec_central_difference(h, n, rm=0.0, **_):  # SOFA CentralDifference with Rayleigh mass
    cst_vel = (1.0 / h - rm / 2.0) / (1.0 / h + rm / 2.0)
    cst_acc = 1.0 / (1.0 / h + rm / 2.0)
    y, out = 1.0, [1.0]
    vh = 0.0 - 0.5 * h * (acc(1.0) - rm * 0.0)  # v_{-1/2} from v_0 = 0
    for _ in range(n):
        vh = cst_vel * vh + cst_acc * acc(y)
        y = y + h * vh
        out.append(y)
    return out


def rec_implicit_euler(h, n, rm=0.0, rk=0.0, **_):  # SOFA EulerImplicit (Baraff-Witkin)
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        dv = h * (F(y) - (h + rk) * K * v - rm * M * v) / ((1.0 + h * rm) * M + h * (h + rk) * K)
        v = v + dv
        y = y + h * v
        out.append(y)
    return out


def rec_exact_implicit_euler(h, n, **_):  # m (y+ - y - h v) = h^2 F(y+), solved in closed form
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        y_new = (M * (y + h * v) + h * h * (K - M * G)) / (M + h * h * K)
        v, y = (y_new - y) / h, y_new
        out.append(y)
    return out


def rec_newmark(h, n, rm=0.0, rk=0.0, beta=0.25, gamma=0.5, **_):  # SOFA Newmark
    y, v = 1.0, 0.0
    a = (F(y) - rm * M * v - rk * K * v) / M
    out = [y]
    for _ in range(n):
        cst_acc = -rm * (1 - gamma) * M - h * (0.5 - beta) * K - rk * (1 - gamma) * K
        cst_vel = -rm * M - (h + rk) * K
        a_new = (F(y) + h * cst_acc * a + cst_vel * v) / ((h * h * beta + h * gamma * rk) * K
                                                           + (1 + h * gamma * rm) * M)
        y = y + h * v + 0.5 * h * h * (1 - 2 * beta) * a + h * h * beta * a_new
        v = v + h * (1 - gamma) * a + h * gamma * a_new
        a = a_new
        out.append(y)
    return out


def rec_variational_symplectic(h, n, **_):  # implicit midpoint, SOFA/Kharevych
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        # (4m/h^2)(q* - y) - F(q*) - (2/h) m v = 0 with F linear
        q = ((4 * M / h ** 2) * y + K - M * G + (2 / h) * M * v) / (4 * M / h ** 2 + K)
        vbar = 2 * (q - y) / h
        y, v = y + h * vbar, 2 * vbar - v
        out.append(y)
    return out


def rec_fast_mass_spring(h, n, iterations=3, **_):  # Liu's global step with the fixed end eliminated
    y, v, out = 1.0, 0.0, [1.0]
    for _ in range(n):
        yy = y + h * v
        yi = yy
        for _ in range(iterations):
            yi = (M * yy + h * h * (F(yi) + K * yi)) / (M + h * h * K)
        v, y = (yi - y) / h, yi
        out.append(y)
    return out


CASES = [
    ("explicit_euler", {}, {}, rec_explicit_euler),
    ("symplectic_euler", {}, {}, rec_symplectic_euler),
    ("symplectic_euler_position_first", {}, {}, rec_symplectic_euler_position_first),
    ("heun", {}, {}, rec_heun),
    ("midpoint", {}, {}, rec_midpoint),
    ("rk4", {}, {}, rec_rk4),
    ("verlet", {}, {}, rec_verlet),
    ("velocity_verlet", {}, {}, rec_velocity_verlet),
    ("leapfrog", {}, {}, rec_leapfrog),
    ("central_difference", {}, {}, rec_central_difference),
    ("central_difference", {}, {"rm": 0.5}, rec_central_difference),
    ("implicit_euler", {}, {}, rec_implicit_euler),
    ("implicit_euler", {}, {"rm": 0.1, "rk": 0.1}, rec_implicit_euler),
    ("newton", {}, {}, rec_exact_implicit_euler),
    ("newmark", {}, {}, rec_newmark),
    ("newmark", {}, {"rm": 0.1, "rk": 0.1}, rec_newmark),
    ("newmark", {"beta": 0.3, "gamma": 0.6}, {"beta": 0.3, "gamma": 0.6}, rec_newmark),
    ("variational_symplectic", {}, {}, rec_variational_symplectic),
    ("fast_mass_spring", {"iterations": 3}, {"iterations": 3}, rec_fast_mass_spring),
]


def _id(case):
    name, opts, params, _ = case
    extra = ",".join(f"{k}={v}" for k, v in {**opts, **params}.items())
    return f"{name}[{extra}]" if extra else name


@pytest.mark.parametrize("case", CASES, ids=[_id(c) for c in CASES])
def test_trajectory_equals_scalar_recurrence(case):
    name, opts, params, recurrence = case
    rm, rk = params.get("rm", 0.0), params.get("rk", 0.0)
    system = sofa_spring(K, M, G, rm=rm, rk=rk)
    xs, _, _ = run(get_integrator(name, **opts), system, system.x0, np.zeros((2, 2)), H, STEPS)
    expected = np.array(recurrence(H, STEPS, **params))
    assert np.abs(xs[:, 0]).max() == 0.0  # no sideways motion
    np.testing.assert_allclose(xs[:, 1], expected, rtol=0, atol=1e-13)
    # the recurrence is not trivial: the free node travels across the whole oscillation
    assert np.ptp(expected) > 0.5
