"""omega_max by power iteration: analytic single spring, chain vs eigsh, critical step."""

import math

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from femkit.dynamics.stability import critical_dt, estimate_omega_max, omega_upper_bound, scaled_stiffness
from femkit.dynamics.topology import cloth_grid, rope, single_spring


@pytest.mark.parametrize("k, m", [(100.0, 10.0), (1e6, 1.0), (3.0, 0.25)], ids=["sofa", "stiff", "soft"])
def test_single_spring_omega_is_sqrt_k_over_m(k, m):
    s = single_spring(k=k, m=m)
    assert estimate_omega_max(s) == pytest.approx(math.sqrt(k / m), rel=1e-12)
    assert s.omega_max() == pytest.approx(math.sqrt(k / m), rel=1e-12)


@pytest.mark.parametrize("make", [
    lambda: rope(12, 2.0, k=50.0, total_mass=1.2, dim=2),
    lambda: rope(9, 1.0, k=20.0, mass=np.linspace(0.5, 2.0, 9), dim=3, pinned="both"),
    lambda: cloth_grid(6, 5, 1.0, 1.0, k_structural=100.0, k_shear=30.0, k_bending=5.0, total_mass=0.3),
], ids=["rope2d", "rope3d-varmass", "cloth"])
def test_omega_max_matches_eigsh(make):
    s = make()
    # a deformed state so the transverse stiffness is not zero
    x = s.x0 * np.linspace(1.0, 1.1, s.dim)
    S = scaled_stiffness(s, x)
    lam = sla.eigsh(S, k=1, which="LA", tol=1e-12)[0][0]
    est = estimate_omega_max(s, x, iters=5000)
    assert est == pytest.approx(math.sqrt(lam), rel=1e-3)
    assert omega_upper_bound(s, x) >= math.sqrt(lam) * (1 - 1e-12)


def test_chain_analytic_frequency():
    # free-fixed chain of n equal masses: omega_max = 2 sqrt(k/m) sin((2n-1) pi / (2(2n+1)))
    n = 8
    s = rope(n + 1, 1.0, k=40.0, mass=0.5, dim=2)
    expected = 2 * math.sqrt(40.0 / 0.5) * math.sin((2 * n - 1) * math.pi / (2 * (2 * n + 1)))
    assert estimate_omega_max(s, iters=5000) == pytest.approx(expected, rel=1e-6)


def test_critical_dt():
    assert critical_dt(10.0, 2.0) == 0.2
    assert critical_dt(4.0, 2 * math.sqrt(2)) == pytest.approx(math.sqrt(2) / 2)
    assert critical_dt(0.0, 2.0) == math.inf
    assert critical_dt(5.0, math.inf) == math.inf


def test_all_pinned_gives_zero():
    s = rope(3, 1.0, k=1.0, pinned=[0, 1, 2])
    assert estimate_omega_max(s) == 0.0
