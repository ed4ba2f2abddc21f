"""Every bundled Poisson case loads, runs and, with an exact solution, is accurate.

Meshes are coarsened through overrides so the whole file runs in a few seconds; the error
bounds are a priori estimates (C h^2 in L2, C h in H1 for smooth solutions, h^(2/3) at the
L-shape corner) with the constants stated, not numbers copied from a run.
"""

from pathlib import Path

import numpy as np
import pytest

import femkit
from femkit.case.poisson.cross_check import cross_check

CASES = Path(__file__).parents[2] / "cases"
POISSON = sorted(p for p in CASES.glob("poisson_*.yaml"))

# case stem -> (overrides, bound on L2 error, bound on max nodal error) (None: no exact given)
EXPECT = {
    "poisson_unit_square": ({"mesh": {"h": 0.1}}, 1e-2, 1e-2),
    "poisson_lshape": ({"mesh": {"h": 0.1}}, 1e-2, 3e-2),
    "poisson_annulus": ({"mesh": {"h": 0.1}}, 5e-3, 5e-3),
    "poisson_high_contrast": ({"mesh": {"h": 0.08}}, None, None),
    "poisson_plate_mesh_file": ({}, 2e-3, 2e-3),
    # the same smooth solution class as the unit square (cos instead of sin), errors modulo
    # the constant; the nodal error of the mean-shifted solution is not superconvergent here
    "poisson_neumann": ({"mesh": {"h": 0.1}}, 1e-2, 2e-2),
}


def test_every_bundled_poisson_case_is_listed_here():
    assert {p.stem for p in POISSON} == set(EXPECT)


@pytest.mark.parametrize("path", POISSON, ids=[p.stem for p in POISSON])
def test_bundled_case_runs_and_is_accurate(path, tmp_path):
    overrides, l2_bound, nodal_bound = EXPECT[path.stem]
    case = femkit.load_case(path, **overrides)
    result = case.run(output_dir=tmp_path / "out")
    assert result.converged, result.solve.message
    assert (tmp_path / "out" / "result.json").is_file()
    if l2_bound is None:
        assert result.errors is None
        assert "exact" not in case.data
    else:
        assert result.errors["L2"] < l2_bound
        assert result.errors["max_nodal"] < nodal_bound
        assert result.errors["H1_semi"] is not None


def test_lshape_data_vanish_on_the_reentrant_edges_and_match_polar_form():
    case = femkit.load_case(CASES / "poisson_lshape.yaml")
    u = case.functions["exact.u"]
    t = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(u(t, 0 * t), 0.0, atol=1e-15)        # theta = 0
    np.testing.assert_allclose(u(0 * t, -t), 0.0, atol=1e-15)       # theta = 3 pi / 2
    # a point in the third quadrant: theta = 5 pi / 4 (not -3 pi / 4)
    r, th = 0.5, 5 * np.pi / 4
    x, y = np.array([r * np.cos(th)]), np.array([r * np.sin(th)])
    np.testing.assert_allclose(u(x, y), r ** (2 / 3) * np.sin(2 * th / 3), rtol=1e-14)
    gx, gy = case.functions["exact.grad[0]"], case.functions["exact.grad[1]"]
    eps = 1e-6  # central differences of u give its gradient
    np.testing.assert_allclose(gx(x, y), (u(x + eps, y) - u(x - eps, y)) / (2 * eps), rtol=1e-6)
    np.testing.assert_allclose(gy(x, y), (u(x, y + eps) - u(x, y - eps)) / (2 * eps), rtol=1e-6)


def test_plate_neumann_sign_matters():
    """The hole flux uses the outward normal; the opposite sign is far off the exact solution."""
    path = CASES / "poisson_plate_mesh_file.yaml"
    good = femkit.load_case(path).run(write=False)
    flux = femkit.load_case(path).data["boundary"]["neumann"][0]["flux"]
    bad = femkit.load_case(path, boundary={"neumann": [{"tags": ["hole"],
                                                        "flux": f"-({flux})"}]}).run(write=False)
    assert bad.errors["L2"] > 20 * good.errors["L2"]


def test_high_contrast_plain_cg_needs_many_more_iterations_than_amg():
    path = CASES / "poisson_high_contrast.yaml"
    amg = femkit.load_case(path, mesh={"h": 0.08}).run(write=False)
    cg = femkit.load_case(path, mesh={"h": 0.08},
                          solver={"method": "cg", "preconditioner": "none"}).run(write=False)
    k = amg.kappa
    assert k.max() / k.min() == pytest.approx(1e6)
    assert amg.solve.iterations * 5 < cg.solve.iterations


def test_unit_square_cross_check_against_scikit_fem_and_pyamg():
    case = femkit.load_case(CASES / "poisson_unit_square.yaml", mesh={"h": 0.1})
    rows = cross_check(case)
    assert [r.passed for r in rows] == [True] * 4, rows
    assert rows[0].difference < 1e-12 and rows[1].difference < 1e-12
