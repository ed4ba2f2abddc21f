"""A-posteriori estimators: effectivity on every bundled case with an exact solution, asymptotic
exactness of ZZ, hand-computed jumps, kappa robustness against a reference solution, scaling."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.errors import InputError
from femkit.fem import PoissonProblem, assemble_stiffness
from femkit.fem.estimators import ESTIMATORS, estimate, problem_data, residual_estimator, zz_estimator
from femkit.fem.norms import energy_error
from femkit.mesh import Mesh, edges, generate, refine
from femkit.mesh.bisect import Bisection

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the case builders
from _exact_cases import CASES, ROOT  # noqa: E402

SIZES = (0.1, 0.05, 0.025)


def _dim(path, mesh: dict) -> int:
    from femkit.mesh import GEOMETRIES, read_mesh

    if "file" in mesh:
        return read_mesh(path.parent / mesh["file"]).dim
    return GEOMETRIES.get(mesh["geometry"]).dim


def test_every_bundled_exact_case_has_a_builder():
    """(Adaptive cases repeat a problem listed here with ``adaptive:`` added; the tetrahedral
    cases' effectivity is tested in tests/case/test_poisson3d_cases.py.)"""
    names = set()
    for path in sorted((ROOT / "cases").glob("*.yaml")):
        data = yaml.safe_load(path.read_text())
        if (data.get("problem") == "poisson" and "exact" in data and "adaptive" not in data
                and _dim(path, data["mesh"]) == 2):
            names.add(data["name"])
    assert names == set(CASES)


@pytest.mark.parametrize("h", SIZES, ids=lambda h: f"h={h}")
@pytest.mark.parametrize("case", sorted(CASES))
def test_effectivity_of_both_estimators_within_half_to_three(case, h):
    prob, grad = CASES[case](h)
    u, _ = prob.solve("direct")
    err = energy_error(prob.mesh, u, grad)
    for name in ("residual", "zz"):
        eff = estimate(prob, u, name).energy / err
        assert 0.5 <= eff <= 3.0, f"{name} effectivity {eff:.3f} on {case} h={h}"


def test_zz_is_asymptotically_exact_on_the_smooth_unit_square():
    prob, grad = CASES["unit_square"](SIZES[-1])
    u, _ = prob.solve("direct")
    eff = estimate(prob, u, "zz").energy / energy_error(prob.mesh, u, grad)
    assert abs(eff - 1.0) <= 0.1, eff


def test_unscaled_residual_estimator_is_an_upper_bound_on_the_bundled_cases():
    """With c_V = c_J = 1 (Verfürth's form) the estimate overestimates: effectivity > 1."""
    for case in sorted(CASES):
        prob, grad = CASES[case](0.05)
        u, _ = prob.solve("direct")
        est = residual_estimator(prob.mesh, u, c_volume=1.0, c_jump=1.0, **problem_data(prob))
        assert est.energy / energy_error(prob.mesh, u, grad) > 1.0, case


def _two_triangles():
    return Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]), np.array([[0, 1, 2], [0, 2, 3]]),
                boundary_edges=[[0, 1], [1, 2], [2, 3], [3, 0]], boundary_tags=[1, 1, 2, 2],
                tag_names={"low": 1, "high": 2})


def test_residual_jump_and_neumann_terms_by_hand():
    """u = 1 at node 2 only: grad u = (0, 1) on T0 = (0,1,2) and (1, 0) on T1 = (0,2,3).

    The shared diagonal (length sqrt 2, normal (1,-1)/sqrt 2 from T0 to T1) carries the jump
    [grad u . n] = (0 - 1)/sqrt 2 - (1 - 0)/sqrt 2 ... = -sqrt 2, so h_E ||J||^2 = sqrt2 * 2 * sqrt2 = 4,
    shared half and half, times c_J^2. On the Neumann edges (h = 0) kappa du/dn: edge 1-2 (x = 1,
    n = (1, 0)) of T0: 0; edge 2-3 (y = 1, n = (0, 1)) of T1: 0; edges 0-1 (n = (0,-1)) of T0: -1 and
    3-0 (n = (-1, 0)) of T1: -1, each contributing h_E * h_E * 1 = 1.
    """
    m = _two_triangles()
    u = np.array([0., 0., 1., 0.])
    est = residual_estimator(m, u, kappa=2.0, c_volume=1.0, c_jump=1.0)
    # kappa = 2: flux jump 2 * sqrt 2, divided by kappa_E = 2: 4 * 2 = 8; Neumann: (2)^2 / 2 = 2
    np.testing.assert_allclose(est.parts["jump"], [4.0, 4.0], rtol=1e-13)
    np.testing.assert_allclose(est.parts["neumann"], [2.0, 2.0], rtol=1e-13)
    np.testing.assert_allclose(est.parts["volume"], [0.0, 0.0])
    # a Neumann datum equal to kappa du/dn removes the mismatch on that edge; Dirichlet ends too
    est = residual_estimator(m, u, kappa=2.0, c_volume=1.0, c_jump=1.0,
                             neumann=[(["low"], lambda x, y: -2.0 * (y < 1e-12) + 0 * x)],
                             dirichlet_nodes=[0, 3])
    np.testing.assert_allclose(est.parts["neumann"], [0.0, 0.0], atol=1e-13)
    # the volume term: f = 3 on triangles of area 1/2 and h_T = sqrt 2: 2 * 9 / 2 / kappa
    est = residual_estimator(m, u, kappa=2.0, f=3.0, c_volume=1.0, c_jump=1.0)
    np.testing.assert_allclose(est.parts["volume"], [4.5, 4.5], rtol=1e-13)


def test_zz_by_hand_on_two_triangles():
    """Recovered gradient: (0,1) and (1,0) at nodes of one triangle only; (1/2, 1/2) at the two shared."""
    m = _two_triangles()
    est = zz_estimator(m, np.array([0., 0., 1., 0.]))
    # T0: differences (1/2, -1/2) at nodes 0 and 2, 0 at node 1: |T|/12 (2 * 1/2 + |(1, -1)|^2) = 1/8
    np.testing.assert_allclose(est.indicators ** 2, [0.125, 0.125], rtol=1e-13)


def _nested_reference_error(prob, u, levels=2):
    """|||u_ref - u_h||| with u_ref on refine(mesh, levels) (energy of the difference)."""
    fine = refine(prob.mesh, levels)
    ref = PoissonProblem(fine, prob.kappa, prob.f, dirichlet=prob.dirichlet)
    u_ref, _ = ref.solve("direct")
    coarse = prob.mesh
    for _ in range(levels):
        step = Bisection(refine(coarse), np.zeros(0, np.int64), edges(coarse)[0])
        u = step.prolong(u)
        coarse = step.mesh
    d = u_ref - u
    return float(np.sqrt(d @ (assemble_stiffness(fine, prob.kappa) @ d)))


@pytest.mark.parametrize("contrast", [1e2, 1e6], ids=["contrast1e2", "contrast1e6"])
def test_kappa_weighting_keeps_effectivity_under_high_contrast(contrast):
    """The inclusion case (no exact solution): effectivity against a twice-refined reference."""
    mesh = generate("square_with_inclusion", 0.1, radius=0.25)
    prob = PoissonProblem(mesh, {"inclusion": contrast, "matrix": 1.0}, 1.0, dirichlet=[(["boundary"], 0.0)])
    u, _ = prob.solve("direct")
    err = _nested_reference_error(prob, u)
    for name in ("residual", "zz"):
        eff = estimate(prob, u, name).energy / err
        assert 0.5 <= eff <= 3.0, f"{name}: {eff:.3f}"


def _scaled_lshape(s=1.0, c=1.0):
    mesh = generate("l_shape", 0.2)
    mesh = Mesh(s * mesh.points, mesh.triangles, mesh.cell_tags, mesh.boundary_edges,
                mesh.boundary_tags, mesh.tag_names)
    f = lambda x, y: c * (1.0 + x / s) / s ** 2          # noqa: E731
    h = lambda x, y: c * (x / s) / s                     # noqa: E731
    return PoissonProblem(mesh, c * 2.0, f, dirichlet=[(["reentrant"], 0.0)], neumann=[(["outer"], h)])


@pytest.mark.parametrize("name", ["residual", "zz"])
@pytest.mark.parametrize("s, c", [(1e-3, 1.0), (1e3, 1.0), (1.0, 1e-4), (1.0, 1e4)],
                         ids=["domain1e-3", "domain1e3", "kappa_f1e-4", "kappa_f1e4"])
def test_estimate_invariant_to_domain_scaling_and_scales_like_the_energy_norm_with_kappa_and_f(name, s, c):
    """Domain x -> s x with f -> f / s^2, flux -> flux / s: the same u in scaled coordinates and, in
    2D, the same energy norm, so the same indicators. kappa, f and flux times c: u unchanged, energy
    norm times sqrt(c), so indicators / sqrt(c) are unchanged (and so is the Dörfler marking)."""
    ref, scaled = _scaled_lshape(), _scaled_lshape(s=s, c=c)
    u0, _ = ref.solve("direct")
    u1, _ = scaled.solve("direct")
    np.testing.assert_allclose(u1, u0, rtol=1e-9, atol=1e-12 * np.abs(u0).max())
    e0, e1 = estimate(ref, u0, name), estimate(scaled, u1, name)
    np.testing.assert_allclose(e1.indicators / np.sqrt(c), e0.indicators, rtol=1e-7,
                               atol=1e-12 * e0.indicators.max())


def test_per_region_sums_to_the_global_estimate():
    mesh = generate("square_with_inclusion", 0.1, radius=0.25)
    prob = PoissonProblem(mesh, {"inclusion": 10.0, "matrix": 1.0}, 1.0, dirichlet=[(["boundary"], 0.0)])
    u, _ = prob.solve("direct")
    est = estimate(prob, u, "residual")
    regions = est.per_region(mesh)
    assert set(regions) == {"inclusion", "matrix"}
    assert np.isclose(np.hypot(*regions.values()), est.energy, rtol=1e-12)


def test_registry_and_bad_input():
    assert ESTIMATORS.names() == ["residual", "zz"]
    m = _two_triangles()
    with pytest.raises(InputError, match="one value per node"):
        zz_estimator(m, np.zeros(3))
    with pytest.raises(InputError, match="non-finite"):
        residual_estimator(m, np.array([0., np.nan, 0., 0.]))
    with pytest.raises(InputError, match="unknown error estimator 'kelly'"):
        ESTIMATORS.get("kelly")


@pytest.mark.parametrize("tags", [[3, 1, 3, 7], [0, 0, 0], [-2, 5, -2], [2 ** 21, 4, 4], []],
                         ids=["small", "one-tag", "negative", "beyond-counting", "empty"])
@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_region_tags_are_listed_as_np_unique_lists_them(tags, dtype):
    from femkit.fem.estimators.base import _distinct

    t = np.array(tags, dtype=dtype)
    got, ref = _distinct(t), np.unique(t)
    assert got.dtype == ref.dtype and np.array_equal(got, ref)
