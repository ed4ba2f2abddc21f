"""Pure-Neumann Poisson problems: compatibility check, the constant fixed, errors modulo it.

Exact solution ``u = cos(pi x) cos(pi y)`` on the unit square: zero normal derivative on every
side and mean zero, ``f = 2 pi^2 u``. Structured meshes (no gmsh), so the file runs in a second.
"""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import InputError, SingularSystemError
from femkit.fem import error_norms
from femkit.fem.poisson import (PoissonProblem, PureNeumannError, check_compatibility, mean_shift,
                                node_weights)

PI = np.pi


def u_exact(x, y):
    return np.cos(PI * x) * np.cos(PI * y)


def grad_exact(x, y):
    return -PI * np.sin(PI * x) * np.cos(PI * y), -PI * np.cos(PI * x) * np.sin(PI * y)


def source(x, y):
    return 2 * PI**2 * u_exact(x, y)


def solve(mesh, nullspace="mean_zero", method="direct", preconditioner=None, **kw):
    prob = PoissonProblem(mesh, 1.0, source, dirichlet=[], nullspace=nullspace, **kw)
    u, res = prob.solve(method, preconditioner, rtol=1e-12)
    assert res.converged, res.message
    return u, prob


def errors_mod_constant(mesh, u):
    return error_norms(mesh, u - mean_shift(mesh, u, u_exact), u_exact, grad_exact)


SOLVERS = [("direct", None), ("cg", None), ("pcg", "amg"), ("pcg", "ic0")]


@pytest.mark.parametrize("method,pc", SOLVERS, ids=[f"{m}-{p}" for m, p in SOLVERS])
def test_rates_are_2_in_L2_and_1_in_H1(make_square, method, pc):
    ns = [4, 8, 16, 32]
    errs = [errors_mod_constant(m, solve(m, method=method, preconditioner=pc)[0])
            for m in map(make_square, ns)]
    h = 1.0 / np.array(ns)
    l2 = np.polyfit(np.log(h), np.log([e["L2"] for e in errs]), 1)[0]
    h1 = np.polyfit(np.log(h), np.log([e["H1_semi"] for e in errs]), 1)[0]
    assert abs(l2 - 2) < 0.1 and abs(h1 - 1) < 0.1, (l2, h1)
    assert errs[-1]["L2"] < 2e-3


def test_mean_zero_solution_has_zero_mean_and_solves_K(make_square):
    mesh = make_square(8)
    for method in ("direct", "cg"):
        u, prob = solve(mesh, method=method)
        w = node_weights(mesh)
        assert abs(w @ u) < 1e-12 * np.abs(u).max()
        assert prob.system.bordered == (method == "direct")
    # the bordered matrix is symmetric indefinite (the multiplier's zero diagonal)
    A = solve(mesh, method="direct")[1].system.A.toarray()
    assert A.shape == (mesh.n_points + 1,) * 2 and A[-1, -1] == 0
    eig = np.linalg.eigvalsh(A)
    assert eig.min() < 0 < eig.max()


@pytest.mark.parametrize("method,pc", SOLVERS, ids=[f"{m}-{p}" for m, p in SOLVERS])
def test_pin_and_mean_zero_agree_modulo_the_constant(make_square, method, pc):
    mesh = make_square(8)
    u_mean, _ = solve(mesh, "mean_zero", method, pc)
    u_pin, prob = solve(mesh, "pin", method, pc, pin_node=5, pin_value=0.75)
    assert u_pin[5] == 0.75
    d = u_pin - u_mean
    assert np.ptp(d) < 1e-9, np.ptp(d)
    # and the pinned solution is exactly the mean-zero one shifted: errors modulo c agree
    e1, e2 = errors_mod_constant(mesh, u_mean), errors_mod_constant(mesh, u_pin)
    assert e1["L2"] == pytest.approx(e2["L2"], rel=1e-8)


def test_incompatible_data_raise_with_both_integrals(make_square):
    mesh = make_square(8)
    prob = PoissonProblem(mesh, 1.0, 1.0, dirichlet=[], neumann=[("bottom", 0.0)])
    with pytest.raises(SingularSystemError) as info:
        prob.solve()
    msg = str(info.value)
    assert isinstance(info.value, InputError) and isinstance(info.value, PureNeumannError)
    assert "int f dx = 1" in msg and "int h ds = 0" in msg and "\n" not in msg


@pytest.mark.parametrize("flux,ok", [(-0.5, True), (+0.5, False)], ids=["balanced", "wrong-sign"])
def test_fluxes_balance_the_source(make_square, flux, ok):
    """-lap u = 1 with u = -(x^2 + y^2)/4: du/dn = -1/2 on right and top, 0 on left and bottom."""
    def exact(x, y):
        return -(x**2 + y**2) / 4

    def grad(x, y):
        return -x / 2, -y / 2

    errs = []
    for n in (8, 16):
        mesh = make_square(n)
        prob = PoissonProblem(mesh, 1.0, 1.0, dirichlet=[], neumann=[(["right", "top"], flux)])
        if not ok:
            with pytest.raises(PureNeumannError, match="int h ds = 1"):
                prob.solve()
            return
        u, res = prob.solve()
        e = error_norms(mesh, u - mean_shift(mesh, u, exact), exact, grad)
        errs.append(e["L2"])
    assert errs[1] < errs[0] / 3.5 and errs[1] < 1e-3


def test_quadrature_remainder_is_removed_and_reported(make_square):
    mesh = make_square(4)
    _, prob = solve(mesh)
    info = prob.system.compatibility
    assert 0 < info["relative_imbalance"] < 1e-3
    assert info["flux_integral"] == 0
    F = prob.system.b[:-1]
    assert abs(F.sum()) < 1e-13


def test_check_compatibility_tolerance():
    F = np.array([1.0, -1.0 + 1e-4])
    with pytest.raises(PureNeumannError, match="relative imbalance"):
        check_compatibility(F, rtol=1e-6)
    G, info = check_compatibility(F, weights=np.array([1.0, 3.0]), rtol=1e-3)
    assert G.sum() == pytest.approx(0.0, abs=1e-15)
    assert G[1] - F[1] == pytest.approx(3 * (G[0] - F[0]))  # removed as a constant source


def test_nullspace_error_and_misuse(make_square):
    mesh = make_square(4)
    with pytest.raises(PureNeumannError, match="mean_zero"):
        PoissonProblem(mesh, f=1.0, dirichlet=[], nullspace="error")
    with pytest.raises(InputError, match="only applies to pure-Neumann"):
        PoissonProblem(mesh, f=1.0, nullspace="pin")
    with pytest.raises(InputError, match="valid modes"):
        PoissonProblem(mesh, f=1.0, dirichlet=[], nullspace="zero_mean")
