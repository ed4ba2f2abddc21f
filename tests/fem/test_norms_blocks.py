"""The error norms and the residual estimator integrate block by block and share the gradient
error between the errors and the energy error; none of it changes a number."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from femkit.fem import energy_error, error_norms
from femkit.fem.estimators import ESTIMATORS
from femkit.mesh import structured_mesh

quadrature = importlib.import_module("femkit.fem.quadrature")


def exact(x, y):
    return np.sin(np.pi * x) * np.sin(2 * np.pi * y)


def grad(x, y):
    return (np.pi * np.cos(np.pi * x) * np.sin(2 * np.pi * y),
            2 * np.pi * np.sin(np.pi * x) * np.cos(2 * np.pi * y))


def source(x, y):
    return 5 * np.pi ** 2 * exact(x, y)


@pytest.fixture
def case():
    mesh = structured_mesh(20, 20)
    u = exact(*mesh.points.T) + 1e-3 * np.cos(7 * mesh.points[:, 0])
    return mesh, u


def test_block_size_does_not_change_the_numbers(monkeypatch, case):
    mesh, u = case
    whole = error_norms(mesh, u, exact, grad)
    est_whole = ESTIMATORS.get("residual")(mesh, u, f=source).indicators
    monkeypatch.setattr(quadrature, "BLOCK", 37)  # many blocks, the last one partial
    assert len(quadrature.blocks(mesh.n_cells)) > 10
    blocked = error_norms(mesh, u, exact, grad)
    est_blocked = ESTIMATORS.get("residual")(mesh, u, f=source).indicators
    for k in whole:
        assert blocked[k] == pytest.approx(whole[k], rel=1e-13)
    np.testing.assert_allclose(est_blocked, est_whole, rtol=1e-13)


def test_energy_error_after_the_errors_is_the_same_number(case):
    mesh, u = case
    fresh = energy_error(mesh, u, grad, kappa=3.0)
    h1 = error_norms(mesh, u, exact, grad)["H1_semi"]
    shared = energy_error(mesh, u, grad, kappa=3.0)
    assert shared == pytest.approx(fresh, rel=1e-14)
    assert shared == pytest.approx(np.sqrt(3.0) * h1, rel=1e-13)


def test_the_shared_gradient_error_follows_u(case):
    mesh, u = case
    error_norms(mesh, u, exact, grad)
    v = u.copy()
    v[5] += 1.0  # another discrete solution on the same mesh: nothing reused for it
    expected = error_norms(mesh, v, exact, grad)["H1_semi"]
    assert energy_error(mesh, v, grad) == pytest.approx(expected, rel=1e-13)
    assert energy_error(mesh, v, grad) != pytest.approx(energy_error(mesh, u, grad), rel=1e-6)
