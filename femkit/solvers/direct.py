"""Direct sparse solve with SciPy's SuperLU, and a reusable factorisation.

For a symmetric matrix with a positive diagonal (the SPD systems femkit assembles) the
factorisation uses ``permc_spec="MMD_AT_PLUS_A"``, ``SymmetricMode`` and threshold
pivoting with ``diag_pivot_thresh=`` :data:`DIAG_PIVOT_THRESH` (a symmetric ordering with
diagonal pivots, about 2x faster than the COLAMD default on 2D Poisson per REFERENCE.md);
otherwise SuperLU's defaults (COLAMD, partial pivoting). The threshold matters: a symmetric
matrix with a positive diagonal need not be positive definite, and pure diagonal pivoting
(threshold 0) then takes tiny pivots (``[[e, 1], [1, e]]``, cond 1, lost ``1/e`` of accuracy);
with the threshold SuperLU swaps such a pivot out, while on SPD/M-matrices the diagonal
always passes it (same fill, same time).

Time-stepping code factors once and reuses the factor::

    F = factorize(K)          # a Factor (femkit.solvers.factor)
    x = F.solve(b)            # many times
    res = direct(K, b, factorization=F)   # same, as a SolveResult
"""

from __future__ import annotations


import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError
from .core.checks import (SYMMETRY_TOL, as_operator, asymmetry, dependency_boundary, finish, prepare,
                     zero_rhs_result)
from .factor import Factor
from .core.result import SolveResult

#: SuperLU ``diag_pivot_thresh`` in symmetric mode: the diagonal is the pivot unless it is below
#: this fraction of the largest entry of its column.
DIAG_PIVOT_THRESH = 1e-3


class SuperLUFactor(Factor):
    """An LU (or symmetric-mode LU) factorisation by SuperLU (the :class:`~femkit.solvers.factor.Factor`
    interface; no separate numeric phase, so :meth:`refactor` is not offered).

    Attributes
    ----------
    shape : tuple
    symmetric : bool
        Whether the symmetric ordering/pivoting was used.
    setup_time : float
        Seconds spent factorising.
    info : dict
        ``nnz_A``, ``nnz_L``, ``nnz_U``, ``fill_ratio``, ``permc_spec``, ``symmetric``.
    """

    def __init__(self, lu, shape, symmetric: bool, setup_time: float, info: dict):
        self._lu = lu
        self.shape = shape
        self.symmetric = symmetric
        self.setup_time = setup_time
        self.info = info

    @property
    def perm_c(self) -> np.ndarray:
        """SuperLU's column permutation; ``A[p][:, p]`` with ``p = argsort(perm_c)`` factorised
        with ``permc_spec="NATURAL"`` reuses this ordering (same fill) for a matrix of equal pattern."""
        return self._lu.perm_c

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(b)


def factorize(A, *, spd: bool | None = None, permc_spec: str | None = None) -> Factor:
    """Factorise a square sparse (or dense) matrix with SuperLU.

    Parameters
    ----------
    A : sparse matrix or ndarray, shape (n, n)
    spd : bool, optional
        ``True``: the caller states that ``A`` is symmetric positive definite, and gets its
        sparse Cholesky factor (:func:`femkit.solvers.cholesky.factorize_spd`, CHOLMOD, the
        symbolic analysis cached per pattern), or :class:`~femkit.errors.NotSPDError` if it is
        not (never a silent switch to LU). ``None`` (default): SuperLU, with the symmetric
        ordering and diagonal pivoting (threshold :data:`DIAG_PIVOT_THRESH`) when ``A`` is
        symmetric to 1e-10 with a positive diagonal. ``False``: SuperLU's general LU.
    permc_spec : str, optional
        SuperLU column ordering overriding the default (``"MMD_AT_PLUS_A"`` for SPD,
        ``"COLAMD"`` otherwise); ``"NATURAL"`` for a matrix the caller has already permuted
        with an ordering it reuses across many factorisations of the same pattern.

    Raises
    ------
    SingularSystemError
        SuperLU finds an exactly zero pivot.
    NotSPDError
        ``spd=True`` and ``A`` is not symmetric positive definite.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> F = factorize(sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(4, 4)))
    >>> F.symmetric, np.round(F.solve(np.ones(4)), 12).tolist()
    (True, [2.0, 3.0, 3.0, 2.0])
    """
    if spd is True:
        if permc_spec is not None:
            raise InputError("permc_spec is a SuperLU option; spd=True factorises by Cholesky")
        from .cholesky import factorize_spd

        return factorize_spd(A)
    return superlu_factor(A, symmetric=spd, permc_spec=permc_spec)


def superlu_factor(A, *, symmetric: bool | None = None, permc_spec: str | None = None) -> Factor:
    """SuperLU factor of ``A``: symmetric mode (``MMD_AT_PLUS_A``, diagonal pivoting with
    threshold :data:`DIAG_PIVOT_THRESH`) when ``symmetric`` is true (``None``: symmetric to
    1e-10 with a positive diagonal), general LU (``COLAMD``, partial pivoting) otherwise."""
    from scipy.sparse.linalg import splu

    spd = symmetric
    if isinstance(A, LinearOperator):
        raise InputError("the direct solver needs an explicit matrix, not a LinearOperator")
    Ac = sp.csc_matrix(as_operator(A))
    Ac.sum_duplicates()
    if not np.all(np.isfinite(Ac.data)):
        raise InputError("A has non-finite entries")
    if spd is None:
        spd = bool(np.all(Ac.diagonal() > 0) and asymmetry(Ac) <= SYMMETRY_TOL)
    t0 = time.perf_counter()
    # "Factor is exactly singular" (a RuntimeError of scipy) -> SingularSystemError, cause kept
    with dependency_boundary("direct factorisation (SuperLU)"):
        if spd:
            permc = permc_spec or "MMD_AT_PLUS_A"
            lu = splu(Ac, permc_spec=permc, diag_pivot_thresh=DIAG_PIVOT_THRESH,
                      options=dict(SymmetricMode=True))
        else:
            permc = permc_spec or "COLAMD"
            lu = splu(Ac, permc_spec=permc)
    dt = time.perf_counter() - t0
    info = {"nnz_A": int(Ac.nnz), "nnz_L": int(lu.L.nnz), "nnz_U": int(lu.U.nnz),
            "fill_ratio": float((lu.L.nnz + lu.U.nnz) / max(Ac.nnz, 1)),
            "permc_spec": permc, "symmetric": bool(spd)}
    return SuperLUFactor(lu, Ac.shape, bool(spd), dt, info)


def direct(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None,
           maxiter=None, M=None, callback=None, factorization: Factor | None = None,
           spd: bool | None = None) -> SolveResult:
    """Solve ``A x = b`` with a sparse LU factorisation (see :func:`factorize`).

    ``x0``, ``maxiter``, ``M`` and ``callback`` are accepted for signature uniformity and
    ignored (``maxiter`` is still validated) (``callback`` is never called: there are no iterations). The stopping rule
    ``||b - A x|| <= max(rtol ||b||, atol)`` is applied to the true residual of the
    returned ``x``: ``converged`` is False (with the residual in ``message``) for a
    numerically singular matrix. ``reason`` is ``"direct"`` either way.

    Parameters
    ----------
    factorization : Factor, optional
        A factor of this ``A`` from :func:`factorize`, reused instead of factorising again.
        ``info["factorization"]`` of the result holds the factor used, for reuse.
    spd : bool, optional
        SuperLU's symmetric mode (``True``), general LU (``False``) or automatic (``None``),
        see :func:`superlu_factor`; the SPD Cholesky path is the ``cholesky`` method.

    Raises
    ------
    SingularSystemError
        Exactly singular matrix.
    """
    prob = prepare(A, b, None, rtol=rtol, atol=atol, maxiter=maxiter, method="direct")
    if isinstance(prob.A, LinearOperator):
        raise InputError("the direct solver needs an explicit matrix, not a LinearOperator")
    if prob.b_is_zero:
        res = zero_rhs_result(prob, method="direct")
        res.reason = "direct"
        return res
    if factorization is None:
        factorization = superlu_factor(prob.A, symmetric=spd)
        setup = factorization.setup_time
    else:
        if tuple(factorization.shape) != prob.A.shape:
            raise InputError(f"factorization is {factorization.shape}, A is {prob.A.shape}")
        setup = 0.0
    t0 = time.perf_counter()
    prob.x = factorization.solve(prob.b)
    dt = time.perf_counter() - t0
    bad = not np.all(np.isfinite(prob.x))
    res = finish(prob, iterations=0, residuals=[prob.rhs_norm], method="direct",
                 reason="converged", info={**factorization.info, "factorization": factorization})
    if res.converged:
        res.reason = "direct"
        res.message = f"direct solve, true residual {res.true_residual:.3e}"
    else:
        res.reason = "non-finite" if bad else "direct"
        res.message = (f"direct solve: true residual {res.true_residual:.3e} exceeds tolerance "
                       f"{res.tolerance:.3e}; the matrix is numerically singular or very "
                       f"ill-conditioned")
    res.setup_time, res.solve_time = setup, dt
    return res
