"""Geometric multigrid (gmg-PCG, fmg) in convergence studies: the study's uniform refinements are
the hierarchy; levels that are not nested are refused at load time, before any work."""

from __future__ import annotations

import re

import numpy as np
import pytest

from femkit.errors import HierarchyError
from femkit.study import run_study, study_from_dict

from .test_poisson_study import SMOOTH

MG = {**SMOOTH, "levels": {"h0": 0.25, "count": 4}, "reference": "none",
      "quadrature": ["barycentric"],
      "solvers": [{"method": "pcg", "preconditioner": "gmg", "rtol": 1e-10}, {"method": "fmg"},
                  {"method": "direct"}]}


@pytest.fixture(scope="module")
def mg_study(tmp_path_factory):
    return run_study(study_from_dict(MG, name="mg"), tmp_path_factory.mktemp("mg") / "report")


def test_gmg_pcg_equals_the_direct_solution_on_every_level(mg_study):
    direct = mg_study.column("L2", source="femkit", solver="direct", quadrature="barycentric")
    gmg = mg_study.column("L2", source="femkit", solver="pcg+gmg", quadrature="barycentric")
    np.testing.assert_allclose(gmg, direct, rtol=1e-6)
    its = mg_study.column("iterations", source="femkit", solver="pcg+gmg", quadrature="barycentric")
    assert its.max() <= 12 and its[-1] <= its[1] + 2  # level-independent, unlike CG's O(1/h)


def test_fmg_stops_at_the_discretisation_error_on_every_level(mg_study):
    direct = mg_study.column("L2", source="femkit", solver="direct", quadrature="barycentric")
    fmg = mg_study.column("L2", source="femkit", solver="fmg", quadrature="barycentric")
    assert np.all(np.abs(fmg / direct - 1) <= 0.2), fmg / direct  # issue 9: within 1.2x
    fit = mg_study.fit(source="femkit", solver="fmg", quadrature="barycentric", norm="L2")
    assert abs(fit["slope"] - 2.0) < 0.15
    assert all(r["converged"] for r in mg_study.records if r["solver"] == "fmg")


def test_nested_iteration_runs_with_the_gmg_preconditioner(mg_study):
    rows = [n for n in mg_study.tables["nested"] if n["solver"] == "pcg+gmg" and n["level"] > 0]
    assert len(rows) == 3
    for n in rows:
        assert 0 < n["algebraic_over_discretisation"] <= 0.1, n
        assert n["iterations_nested"] <= n["iterations_fixed"], n


@pytest.mark.parametrize("patch, text", [
    ({"levels": {"h": [0.5, 0.25]}}, "levels: {h: [...]} gives independent gmsh meshes"),
    ({"solvers": [{"method": "cg"}, {"method": "pcg", "preconditioner": "gmg"}],
      "levels": {"h": [0.5, 0.25]}}, "solvers[1]: preconditioner 'gmg' needs nested meshes"),
], ids=["fmg-on-gmsh-levels", "gmg-on-gmsh-levels"])
def test_multigrid_on_levels_that_are_not_nested_is_refused_at_load(patch, text, tmp_path):
    with pytest.raises(HierarchyError, match=re.escape(text)) as info:
        run_study(study_from_dict({**MG, **patch}), tmp_path / "r")
    assert "amg_rs" in str(info.value)
    assert not (tmp_path / "r").exists()


def test_multigrid_in_an_adaptive_study_is_refused_at_load(tmp_path):
    data = {"kind": "adaptive", "problem": {k: v for k, v in SMOOTH["problem"].items() if k != "exact"},
            "h0": 0.25, "estimators": ["residual"], "theta": 0.5, "max_dofs": 2000,
            "solvers": [{"method": "fmg"}]}
    with pytest.raises(HierarchyError, match="graded meshes"):
        run_study(study_from_dict(data), tmp_path / "r")
