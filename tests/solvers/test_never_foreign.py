"""Never a foreign exception (issue 18, part 3).

Every registered solver and preconditioner name on the same set of awkward matrices (zero
diagonal, negative definite, indefinite, nonsymmetric, singular, NaN entries): a femkit error, or
an honest result (a known reason, ``converged`` only when the true residual meets the rule),
never an exception of a dependency. A dependency's exception survives as the cause.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import FemkitError, NotSPDError, SingularSystemError
from femkit.solvers import PRECONDITIONERS, REASONS, SOLVERS, solve
from femkit.solvers.core.checks import dependency_boundary

from .conftest import poisson_2d


def _saddle_point() -> sp.csr_matrix:
    """``[[K, B^T], [B, 0]]``: symmetric, indefinite, a zero diagonal block."""
    K = poisson_2d(8)
    n = K.shape[0]
    B = sp.random(n // 4, n, density=0.05, random_state=1, format="csr") + sp.eye(n // 4, n)
    return sp.bmat([[K, B.T], [B, None]], format="csr")


def _matrix_set() -> dict[str, sp.csr_matrix]:
    K = poisson_2d(8)
    n = K.shape[0]
    zero_diag = K.tolil()
    zero_diag.setdiag(0.0)
    singular = K.tolil()
    singular[0, :] = 0.0
    singular[:, 0] = 0.0
    nan = K.copy()
    nan.data[3] = np.nan
    return {
        "saddle-point": _saddle_point(),
        "zero-diagonal": zero_diag.tocsr(),
        "negative-definite": (-K).tocsr(),
        "indefinite": (K - 3.0 * sp.identity(n)).tocsr(),
        "nonsymmetric": (K + sp.random(n, n, density=0.05, random_state=2)).tocsr(),
        "singular": singular.tocsr(),
        "nan-entries": nan,
    }


MATRICES = _matrix_set()


def _names():
    out = []
    for method in SOLVERS.names():
        for pc in (PRECONDITIONERS.names() if method == "pcg" else [None]):
            out.append(pytest.param(method, pc, id=f"{method}{'-' + pc if pc else ''}"))
    return out


@pytest.mark.parametrize("matrix", list(MATRICES))
@pytest.mark.parametrize("method, pc", _names())
def test_a_femkit_error_or_an_honest_result(method, pc, matrix):
    A = MATRICES[matrix]
    b = np.ones(A.shape[0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = solve(A, b, method=method, preconditioner=pc)
        except FemkitError as exc:
            assert str(exc)
            return
    assert res.reason in REASONS
    assert np.all(np.isfinite(res.x)) or res.reason == "non-finite"
    if res.converged:
        assert np.linalg.norm(b - A @ res.x) <= res.tolerance * (1 + 1e-12)


def test_issue_amg_rs_on_a_saddle_point_matrix():
    # issue 18: pcg + amg_rs on a symmetric matrix with a zero diagonal let pyamg's
    # "ValueError: array must not contain infs or NaNs" escape
    A = MATRICES["saddle-point"]
    with pytest.raises(NotSPDError, match="zero, negative or non-finite diagonal") as info:
        solve(A, np.ones(A.shape[0]), method="pcg", preconditioner="amg_rs")
    assert isinstance(info.value.__cause__, ValueError)      # pyamg's message kept as the cause
    assert "infs or NaNs" in str(info.value)


def test_superlu_singular_keeps_its_cause():
    S = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    with pytest.raises(SingularSystemError, match="singular") as info:
        solve(S, np.ones(2), method="direct")
    assert isinstance(info.value.__cause__, RuntimeError)


def test_own_bugs_are_not_disguised():
    # an exception raised by femkit's own code (or the caller's) passes the boundary unchanged
    with pytest.raises(ZeroDivisionError):
        with dependency_boundary("an example"):
            1 / 0
