"""One Factor interface for every factorisation femkit keeps: SuperLU, CHOLMOD, PARDISO and the
permuted factor answer ``solve`` for one or a block of right-hand sides like SciPy's
``spsolve``, refuse a right-hand side of the wrong length with the same message, and
(where the engine has a numeric phase) refactorise new values on the same pattern."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from femkit.errors import InputError
from femkit.solvers import Factor, factorize, factorize_spd
from femkit.solvers.factor import PermutedFactor

from .conftest import poisson_2d


def _superlu(A):
    return factorize(A)


def _permuted(A):
    p = np.random.default_rng(3).permutation(A.shape[0])
    return PermutedFactor(factorize(A[p][:, p], permc_spec="NATURAL"), p)


ENGINES = [
    pytest.param(_superlu, id="superlu"),
    pytest.param(_permuted, id="permuted"),
    pytest.param(lambda A: factorize_spd(A), id="cholmod", marks=pytest.mark.cholmod),
    pytest.param(lambda A: factorize_spd(A, engine="pardiso"), id="pardiso",
                 marks=pytest.mark.pardiso),
]


@pytest.mark.parametrize("make", ENGINES)
def test_solve_matches_spsolve_for_one_and_a_block_of_right_hand_sides(make):
    A = poisson_2d(12)
    F = make(A)
    assert isinstance(F, Factor) and F.shape == A.shape and F.symmetric
    B = np.random.default_rng(0).standard_normal((A.shape[0], 3))
    ref = spsolve(A.tocsc(), B)
    np.testing.assert_allclose(F.solve(B), ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(F.solve(B[:, 1]), ref[:, 1], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(F(B[:, 2]), F.matvec(B[:, 2]), rtol=0, atol=0)


@pytest.mark.parametrize("make", ENGINES)
def test_a_right_hand_side_of_the_wrong_length_is_refused_alike(make):
    F = make(poisson_2d(6))
    with pytest.raises(InputError, match=r"^b has 35 rows, the factor is 36 x 36$"):
        F.solve(np.ones(35))
    with pytest.raises(InputError, match=r"^b has 37 rows, the factor is 36 x 36$"):
        F.solve(np.ones((37, 2)))


@pytest.mark.parametrize("make", ENGINES[2:])
def test_refactor_on_the_same_pattern_solves_the_new_matrix_and_counts_the_analysis(make):
    A = poisson_2d(10)
    F = make(A)
    uses = F.symbolic_uses
    A2 = (3.0 * A + sp.identity(A.shape[0])).tocsr()
    assert F.refactor(A2) is F
    assert F.symbolic_uses == uses + 1
    b = np.linspace(-1.0, 1.0, A.shape[0])
    np.testing.assert_allclose(A2 @ F.solve(b), b, atol=1e-11)


@pytest.mark.parametrize("make", ENGINES[:2])
def test_superlu_factors_have_no_numeric_phase_to_refactor(make):
    with pytest.raises(InputError, match="cannot refactor"):
        make(poisson_2d(4)).refactor(poisson_2d(4))
