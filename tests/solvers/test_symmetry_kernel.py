"""The compiled symmetry check equals the sparse-algebra one: ``||A - A^T||_inf / ||A||_inf``
for symmetric matrices, a one-sided pattern, tiny perturbations and unsorted input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.solvers.core import checks


def _random(n, per_row, state):
    rng = np.random.default_rng(state)
    rows = np.repeat(np.arange(n), per_row)
    cols = rng.integers(0, n, n * per_row)
    return sp.csr_matrix((rng.standard_normal(n * per_row), (rows, cols)), shape=(n, n))


CASES = {
    "nonsymmetric": lambda: _random(3000, 8, 0),
    "symmetric": lambda: (_random(3000, 8, 1) + _random(3000, 8, 1).T).tocsr(),
    "one-sided pattern": lambda: sp.triu(_random(3000, 8, 2), k=1, format="csr"),
    "lower pattern": lambda: sp.tril(_random(3000, 8, 5), format="csr"),
    "perturbed by 1e-9": lambda: (_random(3000, 8, 3) + _random(3000, 8, 3).T
                                  + 1e-9 * _random(3000, 8, 4)).tocsr(),
    "zero": lambda: sp.csr_matrix((3000, 3000)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_compiled_asymmetry_equals_the_sparse_algebra(name, monkeypatch):
    A = CASES[name]()
    monkeypatch.setattr(checks, "SYMMETRY_NUMBA_NNZ", 10**15)
    ref = checks.asymmetry(A)
    monkeypatch.setattr(checks, "SYMMETRY_NUMBA_NNZ", 0)
    got = checks.asymmetry(A)
    assert got == pytest.approx(ref, rel=1e-12, abs=1e-300)
    if name == "symmetric":
        assert got == 0.0
    if name in ("nonsymmetric", "one-sided pattern", "lower pattern"):
        assert got > 0.5


def test_unsorted_duplicate_entries_are_summed_before_the_check(monkeypatch):
    # a_01 stored as two halves, out of order: symmetric after summing
    A = sp.csr_matrix((np.array([0.5, 2.0, 0.5, 1.0, 2.0]), np.array([1, 0, 1, 0, 1]),
                       np.array([0, 3, 5])), shape=(2, 2))
    A.has_canonical_format = False
    monkeypatch.setattr(checks, "SYMMETRY_NUMBA_NNZ", 0)
    assert checks.asymmetry(A) == 0.0


SMALL = {
    "nonsymmetric": lambda n: _random(n, 4, 6),
    "symmetric": lambda n: (_random(n, 4, 7) + _random(n, 4, 7).T).tocsr(),
    "perturbed by 1e-12": lambda n: (_random(n, 4, 8) + _random(n, 4, 8).T
                                     + 1e-12 * _random(n, 4, 9)).tocsr(),
    "unsorted duplicates": lambda n: sp.csr_matrix(
        (np.array([0.5, 2.0, 0.5, 1.0, 2.0]), np.array([1, 0, 1, 0, 1]), np.array([0, 3, 5])),
        shape=(2, 2)),
}


@pytest.mark.parametrize("n", [2, 12, 64], ids=lambda n: f"n{n}")
@pytest.mark.parametrize("name", list(SMALL))
def test_small_matrices_checked_densely_give_the_sparse_algebras_value(name, n, monkeypatch):
    """A small system (a time step of a small scene) is checked as a dense array: the same value
    as the sparse difference, to round-off in the row sums."""
    A = SMALL[name](n)
    monkeypatch.setattr(checks, "SYMMETRY_DENSE_N", 0)
    ref = checks.asymmetry(A)
    monkeypatch.setattr(checks, "SYMMETRY_DENSE_N", 64)
    got = checks.asymmetry(A)
    assert got == pytest.approx(ref, rel=1e-12, abs=1e-300)
    if name in ("symmetric", "unsorted duplicates"):
        assert got == 0.0
    if name == "nonsymmetric":
        assert got > 0.1
    if name == "perturbed by 1e-12":
        assert 0.0 < got < 1e-10
