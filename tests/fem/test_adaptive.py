"""Adaptive loop: energy rates on the L-shape (adaptive N^-1/2, uniform N^-1/3), stopping rules,
nested iteration, Dörfler marking, bad settings."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import AdaptivityError, InputError, UnknownNameError
from femkit.fem.adaptive import adaptive_solve, check_settings, poisson_solver
from femkit.fem.marking import dorfler_mark
from femkit.mesh import generate, quality

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the case builders
from _exact_cases import lshape_grad, lshape_u  # noqa: E402


def _lshape_solver(**opts):
    opts = {"method": "direct", **opts}
    return poisson_solver(1.0, 0.0, dirichlet=[(["boundary"], lshape_u)], **opts)


@pytest.fixture(scope="module")
def lshape_mesh():
    return generate("l_shape", 0.25)


def _rate(run, min_dofs=200):
    N = np.array([lv.dofs for lv in run.levels], float)
    e = np.array([lv.error for lv in run.levels])
    sel = N >= min_dofs
    assert sel.sum() >= 4
    return -np.polyfit(np.log(N[sel]), np.log(e[sel]), 1)[0]


@pytest.mark.parametrize("estimator", ["residual", "zz"])
def test_adaptive_lshape_restores_the_optimal_rate(lshape_mesh, estimator):
    """Optimal P1 rate N^(-1/2) in the energy norm (measured: 0.504 residual, 0.498 zz, up to 11k dofs)."""
    run = adaptive_solve(_lshape_solver(), lshape_mesh, theta=0.5, max_dofs=12000,
                         estimator=estimator, grad_exact=lshape_grad)
    assert run.stop_reason == "max_dofs" and not run.target_met
    assert abs(_rate(run) - 0.5) <= 0.05
    eff = [lv.effectivity for lv in run.levels]
    assert 0.5 <= min(eff) and max(eff) <= 3.0
    assert len(run.levels) >= 15
    # graded towards the corner, shapes kept: NVB's angle bound of the initial mesh (28.59 deg)
    from femkit.mesh.bisect import label_longest_edge, min_angle_bound

    assert quality(run.mesh)["min_angle"] >= min_angle_bound(label_longest_edge(lshape_mesh)) - 1e-9
    assert np.isclose(run.mesh.areas().sum(), 3.0, rtol=1e-13)


def test_uniform_lshape_is_limited_by_the_singularity(lshape_mesh):
    """Uniform refinement: N^(-1/3) (r^(2/3) singularity; measured 0.318)."""
    run = adaptive_solve(_lshape_solver(), lshape_mesh, refinement="uniform", max_levels=5,
                         grad_exact=lshape_grad)
    assert [lv.n_elements for lv in run.levels][1:] == [4 ** k * run.levels[0].n_elements for k in range(1, 5)]
    assert abs(_rate(run) - 1 / 3) <= 0.05


def test_target_met_stops_at_the_first_level_below_it(lshape_mesh):
    run = adaptive_solve(_lshape_solver(), lshape_mesh, theta=0.5, target=0.03)
    est = [lv.estimate for lv in run.levels]
    assert run.target_met and run.stop_reason == "target"
    assert est[-1] <= 0.03 < min(est[:-1])


@pytest.mark.parametrize("budget, reason", [({"max_dofs": 400}, "max_dofs"),
                                            ({"max_levels": 3}, "max_levels"),
                                            ({"max_time": 1e-9}, "max_time")],
                         ids=["dofs", "levels", "time"])
def test_budget_before_target_is_reported_not_silent(lshape_mesh, budget, reason):
    run = adaptive_solve(_lshape_solver(), lshape_mesh, target=1e-6, **budget)
    assert not run.target_met and run.stop_reason == reason
    assert run.levels[-1].estimate > 1e-6
    if reason == "max_dofs":
        assert all(lv.n_nodes <= 400 for lv in run.levels)
    if reason == "max_levels":
        assert len(run.levels) == 3
    if reason == "max_time":
        assert len(run.levels) == 1


def test_nested_iteration_starts_from_the_interpolated_solution(lshape_mesh):
    """The prolongated previous solution is a far better start than zero: fewer PCG iterations."""
    from femkit.mesh.bisect import bisect, label_longest_edge

    solve_on = _lshape_solver(method="pcg", preconditioner="jacobi", rtol=1e-8)
    coarse = label_longest_edge(lshape_mesh)
    _, u, _ = solve_on(coarse, None)
    step = bisect(coarse, np.arange(coarse.n_triangles))
    _, u_cold, cold = solve_on(step.mesh, None)
    _, u_warm, warm = solve_on(step.mesh, step.prolong(u))
    assert warm.converged and cold.converged
    assert warm.iterations < cold.iterations
    np.testing.assert_allclose(u_warm, u_cold, atol=1e-6)


def test_dorfler_marks_a_minimal_bulk_set():
    rng = np.random.default_rng(7)
    eta = rng.lognormal(size=500)
    for theta in (0.1, 0.5, 0.9):
        marked = dorfler_mark(eta, theta)
        total = np.sum(eta ** 2)
        assert np.sum(eta[marked] ** 2) >= theta * total
        # minimal: dropping the smallest marked indicator falls below the bulk
        assert np.sum(eta[marked[:-1]] ** 2) < theta * total
        assert eta[marked].min() >= np.delete(eta, marked).max()
    assert len(dorfler_mark(eta, 1.0)) == 500
    assert len(dorfler_mark(np.zeros(4), 0.5)) == 0


@pytest.mark.parametrize("kwargs, match", [
    ({"theta": 0.0}, "theta must be in"), ({"theta": -0.2}, "theta must be in"),
    ({"theta": 1.5}, "theta must be in"), ({"theta": math.nan}, "theta must be in"),
    ({"theta": "half"}, "theta must be a number"),
    ({"target": 0.0}, "target must be a positive"), ({"target": -1e-3}, "target must be a positive"),
    ({"max_dofs": 0}, "max_dofs must be a positive integer"), ({"max_dofs": -5}, "max_dofs"),
    ({"max_dofs": 2.5}, "max_dofs must be a positive integer"),
    ({"max_time": 0}, "max_time must be a positive"), ({"max_time": math.inf}, "max_time"),
    ({"max_levels": 0}, "max_levels"), ({"refinement": "red"}, "unknown refinement 'red'"),
], ids=lambda v: str(v) if not isinstance(v, dict) else "-".join(f"{k}={v[k]}" for k in v))
def test_bad_settings_are_one_line_adaptivity_errors(kwargs, match):
    with pytest.raises(AdaptivityError, match=match) as info:
        check_settings(**kwargs)
    assert isinstance(info.value, InputError) and "\n" not in str(info.value)
    with pytest.raises(AdaptivityError):
        adaptive_solve(_lshape_solver(), None, **kwargs)     # checked before any work


def test_unknown_estimator_lists_the_valid_ones():
    with pytest.raises(UnknownNameError, match="valid error estimators: residual, zz"):
        check_settings(estimator="kelly")


def test_per_element_kappa_array_is_refused():
    with pytest.raises(AdaptivityError, match="per-element array"):
        poisson_solver(np.ones(10))


@pytest.mark.parametrize("method", ["pcg", "direct"])
def test_pure_neumann_problem_refines_with_either_solver(method):
    """The nullspace systems (pinned for PCG, bordered for direct) go through the loop too."""
    from _exact_cases import poisson_neumann

    prob, grad = poisson_neumann(0.2)
    solve_on = poisson_solver(prob.kappa, prob.f, dirichlet=[], neumann=prob.neumann,
                              nullspace="mean_zero", method=method)
    run = adaptive_solve(solve_on, prob.mesh, theta=0.5, max_levels=6, grad_exact=grad)
    err = [lv.error for lv in run.levels]
    assert err[-1] < 0.6 * err[0]
    assert all(0.5 <= lv.effectivity <= 3.0 for lv in run.levels)
    assert abs(float(run.problem.system.weights @ run.u)) < 1e-10     # mean zero kept


def test_target_on_true_error_needs_an_exact_gradient(lshape_mesh):
    run = adaptive_solve(_lshape_solver(), lshape_mesh, target=0.05, target_on="error",
                         grad_exact=lshape_grad)
    assert run.target_met and run.levels[-1].error <= 0.05 < run.levels[-2].error
    with pytest.raises(AdaptivityError, match="target_on"):
        adaptive_solve(_lshape_solver(), lshape_mesh, target=0.05, target_on="error")
