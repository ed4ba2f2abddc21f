"""A generated convergence study: rates match P1 theory, data monotone, report renders."""

from __future__ import annotations

import base64
import re
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import CaseFileError, ExpressionError
from femkit.study import load_study, run_study, study_from_dict
from femkit.study.poisson_convergence.run import interpolate_nested

ROOT = Path(__file__).resolve().parents[2]
PNG = b"\x89PNG\r\n\x1a\n"

SMOOTH = {
    "kind": "poisson_convergence",
    "problem": {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
                "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "sin(pi*x)*sin(pi*y)"}]},
                "exact": {"u": "sin(pi*x)*sin(pi*y)",
                          "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}},
    "levels": {"h0": 0.2, "count": 4},
    "solvers": [{"method": "pcg", "preconditioner": "amg", "rtol": 1e-10}, {"method": "cg", "rtol": 1e-10},
                {"method": "pcg", "preconditioner": "ic0", "rtol": 1e-10}, {"method": "direct"}],
    "quadrature": ["barycentric", "gauss3"],
    "reference": "scikit-fem",
    "stop_at_discretisation_error": {"fraction": 0.1},
    "warmup": 0,
}


@pytest.fixture(scope="module")
def smooth(tmp_path_factory):
    out = tmp_path_factory.mktemp("smooth") / "report"
    return run_study(study_from_dict(SMOOTH, name="smooth"), out)


@pytest.mark.parametrize("norm, theory", [("L2", 2.0), ("H1_semi", 1.0)], ids=["L2", "H1"])
@pytest.mark.parametrize("rule", ["barycentric", "gauss3"])
def test_fitted_rates_match_p1_theory(smooth, norm, theory, rule):
    fit = smooth.fit(source="femkit", solver="direct", quadrature=rule, norm=norm)
    assert abs(fit["slope"] - theory) < 0.1
    assert fit["r2"] > 0.99 and fit["n"] == 4


def test_reference_line_agrees_with_femkit(smooth):
    # same meshes, same P1 space: scikit-fem's 3-point load and femkit's gauss3 give the same errors
    ours = smooth.column("L2", source="femkit", solver="direct", quadrature="gauss3")
    ref = smooth.column("L2", source="scikit-fem")
    np.testing.assert_allclose(ref, ours, rtol=1e-6)


@pytest.mark.parametrize("key", ["L2", "H1_semi", "max_nodal", "h"])
def test_finer_mesh_smaller_error(smooth, key):
    for solver in ("pcg+amg", "cg", "direct"):
        v = smooth.column(key, source="femkit", solver=solver, quadrature="barycentric")
        assert np.all(np.diff(v) < 0), (solver, v)
    dofs = smooth.column("dofs", source="femkit", solver="direct", quadrature="barycentric")
    assert np.all(np.diff(dofs) > 0)


def test_iterations_amg_flat_cg_grows(smooth):
    amg = smooth.column("iterations", source="femkit", solver="pcg+amg", quadrature="barycentric")
    cg = smooth.column("iterations", source="femkit", solver="cg", quadrature="barycentric")
    assert amg.max() <= 25
    assert np.all(np.diff(cg) > 0) and cg[-1] / cg[0] > 4  # O(h^-1): x2 per level


def test_every_run_reaches_its_true_residual(smooth):
    for r in smooth.records:
        if r["source"] == "femkit" and r["method"] != "direct":
            assert r["converged"] and r["relative_residual"] <= 1e-10 * (1 + 1e-9)


@pytest.mark.parametrize("solver", ["pcg+amg", "pcg+ic0", "cg"])
def test_nested_iteration_meets_its_target_and_saves(smooth, solver):
    rows = [n for n in smooth.tables["nested"] if n["solver"] == solver and n["level"] > 0]
    assert len(rows) == 3
    for n in rows:
        # the measured algebraic error ||u_nested - u_l||_A (u_l by a direct solve) against the true
        # energy-norm discretisation error: at most the target fraction, no slack needed (the test
        # uses an upper bound of the algebraic error and a lower estimate of the discretisation error)
        assert n["stopped_by_estimate"] and n["bound_over_estimate"] <= 0.1
        assert 0 < n["algebraic_over_discretisation"] <= 0.1, n
        assert n["iterations_nested"] < n["iterations_fixed"], n
        assert n["H1_nested"] <= 1.01 * n["H1_fixed"]  # energy error: at most sqrt(1 + 0.1^2) larger


def test_nested_amg_keeps_l2_accuracy(smooth):
    for n in smooth.tables["nested"]:
        if n["solver"] == "pcg+amg":
            assert n["L2_nested"] <= 1.1 * n["L2_fixed"]


def test_gauss_radau_bound_is_an_upper_bound():
    import scipy.sparse as sp

    from femkit.solvers import SolverSpec
    from femkit.study.poisson_convergence.run import cg_history, gauss_radau_bounds, smallest_ritz_value

    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(15, 15))
    A = (sp.kron(T, sp.eye(15)) + sp.kron(sp.eye(15), T)).tocsr()  # 2D Laplacian: IC(0) is not exact
    n = A.shape[0]
    rng = np.random.default_rng(1)
    b = rng.standard_normal(n)
    x_star = np.linalg.solve(A.toarray(), b)
    for s in ({"method": "cg", "rtol": 1e-12}, {"method": "pcg", "preconditioner": "ic0", "rtol": 1e-12}):
        h = cg_history(A, b, np.zeros(n), SolverSpec.from_mapping(s))
        lam = smallest_ritz_value(h["alpha"], h["rz"])
        U = gauss_radau_bounds(h["inc"], h["rz"], 0.5 * lam)
        xs = [np.zeros(n)]
        from femkit.solvers import solve

        kw = {k: v for k, v in s.items() if k != "method"}
        solve(A, b, np.zeros(n), method=s["method"], callback=lambda x: xs.append(x.copy()), **kw)
        err2 = np.array([(x - x_star) @ (A @ (x - x_star)) for x in xs])
        big = err2 > 1e-20 * err2[0]  # above round-off
        assert np.all(U[big] >= err2[big])
        assert U[big][-1] < 1e-6 * U[0]  # and it falls with the error: informative, not just safe


def test_interpolation_to_refined_mesh_exact_for_linear():
    from femkit.mesh import Mesh, refine

    m = Mesh(points=np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), triangles=np.array([[0, 1, 2], [0, 2, 3]]))
    f = refine(m, 1)
    lin = lambda p: 2 * p[:, 0] - 3 * p[:, 1] + 1  # noqa: E731
    np.testing.assert_allclose(interpolate_nested(m, f, lin(m.points)), lin(f.points), atol=1e-14)


def test_report_files(smooth):
    out = smooth.output_dir
    for name in ("report.md", "report.html", "runs.csv", "results.json", "nested.csv"):
        assert (out / name).stat().st_size > 0
    names = {"error_vs_h.png", "error_vs_dofs.png", "iterations_vs_dofs.png", "work_precision.png"}
    assert {Path(f).name for f in smooth.figures} == names
    html = (out / "report.html").read_text()
    embedded = [base64.b64decode(s) for s in re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", html)]
    assert len(embedded) == 4
    for f in smooth.figures:
        data = (out / f).read_bytes()
        assert data.startswith(PNG) and data in embedded
        import matplotlib.image as mpimg

        img = mpimg.imread(out / f)
        assert img.shape[0] >= 300 and img.shape[1] >= 500 and img.std() > 0.01
    assert any(r["pareto"] for r in smooth.records)


@pytest.mark.parametrize("patch, exc, text", [
    ({"levels": {"h0": 0.2, "cont": 3}}, CaseFileError, "levels.cont: unknown key"),
    ({"solvers": [{"method": "cg", "rtl": 1}]}, CaseFileError, "solvers[0].rtl"),
    ({"reference": "fenics"}, CaseFileError, "reference"),
    ({"problem": {**SMOOTH["problem"], "exact": {"u": "__import__('os')"}}}, ExpressionError, "problem: exact.u"),
], ids=["levels-typo", "solver-typo", "bad-reference", "unsafe-expression"])
def test_bad_study_files(patch, exc, text, tmp_path):
    with pytest.raises(exc, match=re.escape(text)):
        s = study_from_dict({**SMOOTH, **patch})
        run_study(s, tmp_path / "r")
    assert not (tmp_path / "r").exists()


def test_bundled_poisson_study_quick(tmp_path):
    res = load_study(ROOT / "studies" / "poisson_convergence.yaml", quick=True).run(tmp_path / "r")
    fit = res.fit(source="femkit", solver="direct", quadrature="barycentric", norm="H1_semi")
    assert abs(fit["slope"] - 1.0) < 0.15
    assert (tmp_path / "r" / "report.html").exists()


def test_rate_table_groups_solvers_with_equal_fits(smooth):
    from femkit.study.poisson_convergence.report import grouped_rate_rows

    rows = grouped_rate_rows(smooth.fits)
    femkit_rows = [r for r in rows if r[0] != "scikit-fem+pyamg"]
    # 4 solvers x 2 rules x 3 norms fits, all solvers reach the same discretisation error: one row per rule x norm
    assert len(smooth.fits) == 4 * 2 * 3 + 3
    assert [r[0] for r in femkit_rows] == ["all solvers"] * 6
    assert [(r[1], r[2]) for r in femkit_rows[:3]] == [("barycentric", n) for n in ("L2", "H1_semi", "max_nodal")]
    # a solver whose fit differs keeps its own row
    odd = [dict(f, slope=f["slope"] + 0.5) if f["solver"] == "cg" else f for f in smooth.fits]
    names = [r[0] for r in grouped_rate_rows(odd) if r[1] == "barycentric" and r[2] == "L2"]
    assert names == ["pcg+amg, pcg+ic0, direct", "cg"]
    assert (smooth.output_dir / "fits.csv").read_text().count("\n") == len(smooth.fits) + 1
