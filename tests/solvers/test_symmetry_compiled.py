"""The compiled symmetry measure of large CSR matrices is SciPy's ``||A - A^T||_inf / ||A||_inf``."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
import scipy.sparse as sp

checks = importlib.import_module("femkit.solvers.checks")


def _laplacian(n=30):
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    return sp.kronsum(one, one).tocsr()


def _one_sided(A):
    """An entry without its mirror (structurally unsymmetric)."""
    B = A.tolil()
    B[0, 5] = 0.25
    return B.tocsr()


def _perturbed(A):
    B = A.copy()
    B.data[7] *= 1 + 1e-6
    return B


MATRICES = {"symmetric": _laplacian, "one-sided-entry": lambda: _one_sided(_laplacian()),
            "value-off": lambda: _perturbed(_laplacian())}


@pytest.mark.parametrize("name", sorted(MATRICES))
def test_compiled_asymmetry_is_scipys(monkeypatch, name):
    A = MATRICES[name]()
    A.sum_duplicates()
    monkeypatch.setattr(checks, "SYMMETRY_NUMBA_THRESHOLD", 10 ** 12)
    ref = checks.asymmetry(A)
    monkeypatch.setattr(checks, "SYMMETRY_NUMBA_THRESHOLD", 0)
    got = checks.asymmetry(A)
    assert got == pytest.approx(ref, rel=1e-12, abs=0)
    if name != "symmetric":
        assert got > 0
