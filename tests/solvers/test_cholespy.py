"""The ``cholesky`` solver's engine ``cholespy`` (CHOLMOD bundled in a wheel, ``femkit[fast]``):
SciPy's answers through the one Factor interface, a non-SPD matrix refused as NotSPDError, and a
refactorisation that solves the new matrix."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

pytest.importorskip("cholespy", reason="cholespy is not installed: pip install -e '.[fast]'")

from femkit.errors import InputError, NotSPDError  # noqa: E402
from femkit.solvers import Factor, factorize_spd  # noqa: E402
from femkit.solvers.cholesky import cholesky  # noqa: E402
from femkit.solvers.factor import CholespyFactor  # noqa: E402

from .conftest import poisson_2d  # noqa: E402


def test_solves_like_spsolve_for_one_and_a_block():
    A = poisson_2d(12)
    F = factorize_spd(A, engine="cholespy")
    assert isinstance(F, CholespyFactor) and isinstance(F, Factor) and F.symmetric
    B = np.random.default_rng(0).standard_normal((A.shape[0], 3))
    ref = spsolve(A.tocsc(), B)
    np.testing.assert_allclose(F.solve(B), ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(F.solve(B[:, 1]), ref[:, 1], rtol=1e-10, atol=1e-12)
    with pytest.raises(InputError, match=r"^b has 3 rows, the factor is 144 x 144$"):
        F.solve(np.ones(3))


def test_refactor_solves_the_new_matrix_in_place():
    A = poisson_2d(8)
    F = factorize_spd(A, engine="cholespy")
    A2 = (A + sp.diags(np.linspace(1.0, 2.0, A.shape[0]))).tocsr()
    b = np.arange(A.shape[0], dtype=float)
    assert F.refactor(A2) is F and F.info["symbolic_reused"] is False
    np.testing.assert_allclose(F.solve(b), spsolve(A2.tocsc(), b), rtol=1e-10)


def test_not_positive_definite_is_a_femkit_error():
    A = -poisson_2d(6)
    with pytest.raises(NotSPDError, match="not positive definite.*method 'direct'"):
        factorize_spd(A, engine="cholespy")


def test_the_cholesky_solver_takes_the_engine_by_name():
    A = poisson_2d(10)
    b = np.ones(A.shape[0])
    res = cholesky(A, b, engine="cholespy")
    assert res.converged
    np.testing.assert_allclose(res.x, spsolve(A.tocsc(), b), rtol=1e-10)
