"""The ``cholesky`` solver's engine ``pardiso`` (Intel oneMKL PARDISO): the same answers as SuperLU,
its analysis reused by every refactorisation, non-SPD input named, and the implicit integrators
taking the same steps with it as with CHOLMOD."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import InputError, NotSPDError, UnknownNameError
from femkit.solvers import direct, factorize_spd, solve

from .conftest import poisson_2d
from .test_cholesky import SCENES, _scene_matrices

pytestmark = pytest.mark.pardiso  # optional MKL


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_pardiso_equals_superlu_on_bundled_scene_systems(path):
    for label, A in _scene_matrices(path).items():
        b = np.random.default_rng(2).standard_normal(A.shape[0])
        r = solve(A, b, method="cholesky", engine="pardiso", rtol=1e-12)
        assert r.converged and r.info["backend"] == "mkl-pardiso"
        xl = direct(A, b, rtol=1e-12).x
        assert np.linalg.norm(r.x - xl) <= 1e-10 * np.linalg.norm(xl), label


def test_refactorisation_reuses_the_analysis_and_solves_blocks():
    A = poisson_2d(30)
    F = factorize_spd(A, engine="pardiso")
    assert F.info["symbolic_uses"] == 1 and F.info["symbolic_reused"] is False
    assert F.info["nnz_L"] >= A.nnz // 2
    for shift in (1.0, 5.0):
        A2 = (A + shift * sp.identity(A.shape[0])).tocsr()
        F.refactor(A2)
        B = np.random.default_rng(0).standard_normal((A.shape[0], 3))
        np.testing.assert_allclose(A2 @ F.solve(B), B, atol=1e-10)
        np.testing.assert_allclose(A2 @ F.solve(B[:, 0]), B[:, 0], atol=1e-10)
    assert F.info["symbolic_uses"] == 3 and F.info["symbolic_reused"] is True
    with pytest.raises(InputError, match="pattern"):
        F.refactor(poisson_2d(31))


@pytest.mark.parametrize("A", [
    -poisson_2d(6),
    sp.diags([1.0, -1.0, 2.0, 3.0]).tocsr(),
], ids=["negative-definite", "indefinite-diagonal"])
def test_not_positive_definite_raises_not_spd_error(A):
    with pytest.raises(NotSPDError, match="pardiso.*not positive definite"):
        factorize_spd(A, engine="pardiso")


def test_bad_engine_options_raise_named_errors():
    A = poisson_2d(5)
    with pytest.raises(UnknownNameError, match="cholesky engine.*cholmod.*pardiso"):
        factorize_spd(A, engine="umfpack")
    with pytest.raises(InputError, match="mode 'simplicial' is CHOLMOD's"):
        factorize_spd(A, engine="pardiso", mode="simplicial")
    with pytest.raises(UnknownNameError, match="pardiso ordering"):
        factorize_spd(A, engine="pardiso", ordering="natural")
    with pytest.raises(NotSPDError, match="not symmetric"):
        factorize_spd(sp.csr_matrix(np.triu(np.ones((4, 4))) + 3 * np.eye(4)), engine="pardiso")


@pytest.mark.cholmod
@pytest.mark.parametrize("integrator, options", [
    ("implicit_euler", {"fix": "clamp"}),
    ("newton", {}),
    ("fast_mass_spring", {"iterations": 5}),
], ids=["baraff-witkin", "newton", "fast-mass-spring"])
def test_integrators_take_the_same_steps_with_either_engine(integrator, options):
    from femkit.dynamics.forces import Gravity
    from femkit.dynamics.integrators import StepContext, get_integrator
    from femkit.dynamics.topology import cloth_grid
    from femkit.solvers import SolverSpec

    system = cloth_grid(12, 12, 1.0, 1.0, k_structural=1e3, k_shear=1e3, k_bending=1e2,
                        total_mass=1.0, pinned="top_corners", forces=[Gravity(9.81)])
    out = {}
    for engine in ("cholmod", "pardiso"):
        ctx = StepContext(SolverSpec("cholesky", options={"engine": engine}))
        integ = get_integrator(integrator, **options)
        state = integ.start(system, system.x0, system.v0, 0.0, 1 / 30, ctx)
        for _ in range(5):
            state = integ.step(system, state, 1 / 30, ctx)
        out[engine] = state.x
        if integrator != "fast_mass_spring":  # refactorised on the kept analysis every step
            assert ctx.stats["symbolic_reuses"] >= 3
    scale = np.abs(out["cholmod"]).max()
    assert np.abs(out["pardiso"] - out["cholmod"]).max() <= 1e-9 * scale
