"""Review defects: unconverged solves fitted as rates; scikit-fem rows always 'converged'."""

from __future__ import annotations

import pytest

from femkit.study import run_study, study_from_dict

SMOOTH = {"mesh": {"geometry": "unit_square"}, "source": "2*pi**2*sin(pi*x)*sin(pi*y)",
          "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "sin(pi*x)*sin(pi*y)"}]},
          "exact": {"u": "sin(pi*x)*sin(pi*y)",
                    "grad": ["pi*cos(pi*x)*sin(pi*y)", "pi*sin(pi*x)*cos(pi*y)"]}}


def test_unconverged_runs_are_not_fitted_and_are_reported(tmp_path):
    """CG stopped after one iteration: its 'errors' are algebraic; a rate fitted from them is a lie."""
    data = {"kind": "poisson_convergence", "warmup": 0, "problem": SMOOTH,
            "levels": {"h0": 0.25, "count": 3},
            "solvers": [{"method": "cg", "maxiter": 1}, {"method": "direct"}]}
    res = run_study(study_from_dict(data), tmp_path / "r")
    assert not any(r["converged"] for r in res.records if r["solver"] == "cg")
    assert [f for f in res.fits if f["solver"] == "cg"] == []
    assert res.fit(solver="direct", norm="L2")["slope"] > 1.8
    assert any("did not converge" in n and "cg" in n for n in res.notes)
    assert "did not converge" in (tmp_path / "r" / "report.md").read_text()


def test_skfem_reference_converged_flag_is_honest(monkeypatch):
    """The scikit-fem rows claimed converged=True whatever SciPy's CG returned."""
    import scipy.sparse.linalg as spla

    from femkit.study.poisson_convergence import run as poisson

    real_cg = spla.cg

    def one_step_cg(A, b, **kw):
        kw["maxiter"] = 1
        return real_cg(A, b, **kw)

    monkeypatch.setattr(spla, "cg", one_step_cg)
    data = {"kind": "poisson_convergence", "warmup": 0, "problem": SMOOTH,
            "levels": {"h0": 0.25, "count": 2}, "solvers": [{"method": "direct"}], "reference": "scikit-fem"}
    res = poisson.run(study_from_dict(data))
    sk = [r for r in res["records"] if r["source"] == "scikit-fem"]
    assert sk and not any(r["converged"] for r in sk)
    assert all(r["relative_residual"] > 1e-10 for r in sk)


def test_skfem_reference_solves_the_same_system(tmp_path):
    data = {"kind": "poisson_convergence", "warmup": 0, "problem": SMOOTH,
            "levels": {"h0": 0.25, "count": 2}, "solvers": [{"method": "direct"}],
            "quadrature": ["gauss3"], "reference": "scikit-fem"}
    res = run_study(study_from_dict(data), tmp_path / "r", write=False)
    for lvl in (0, 1):
        fk = [r for r in res.records if r["level"] == lvl and r["source"] == "femkit"][0]
        sk = [r for r in res.records if r["level"] == lvl and r["source"] == "scikit-fem"][0]
        assert (sk["dofs"], sk["nnz"], sk["nodes"]) == (fk["dofs"], fk["nnz"], fk["nodes"])
        assert sk["converged"]
        assert sk["L2"] == pytest.approx(fk["L2"], rel=1e-6)  # same P1 space, same 3-point load rule


def test_skfem_reference_is_warmed_up_before_timing(monkeypatch):
    """The first scikit-fem level was timed cold (skfem/pyamg first calls ~2x slower)."""
    from femkit.study.poisson_convergence import run as poisson

    calls = []
    real = poisson._skfem_run
    monkeypatch.setattr(poisson, "_skfem_run", lambda spec, mesh, rtol, repeats: calls.append(mesh.n_points)
                        or real(spec, mesh, rtol, repeats))
    data = {"kind": "poisson_convergence", "warmup": 1, "problem": SMOOTH,
            "levels": {"h0": 0.25, "count": 2}, "solvers": [{"method": "direct"}], "reference": "scikit-fem"}
    res = poisson.run(study_from_dict(data))
    n0, n1 = (r["nodes"] for r in res["records"] if r["source"] == "scikit-fem")
    assert calls == [n0, n0, n1]  # one untimed call first, then one per level
