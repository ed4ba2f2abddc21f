"""Input checks and result assembly shared by every femkit linear solver.

Every method goes through :func:`prepare` (validate ``A``, ``b``, ``x0``, tolerances and
``maxiter``; check symmetry once) and :func:`finish` (recompute the *true* residual and
decide ``converged``), so the stopping rule::

    ||b - A x||_2 <= max(rtol * ||b||_2, atol)

and the error messages are the same for all of them.

Tolerance policy: ``rtol`` and ``atol`` must be finite and non-negative, and at least one
of them positive. ``rtol = atol = 0`` asks for an exact solution, which floating-point
iterations cannot certify, so it raises :class:`~femkit.errors.InputError` instead of
silently running to ``maxiter``.
"""

from __future__ import annotations

from .defaults import DEFAULT_RTOL

import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError, NotSPDError
from .result import SolveResult

#: Relative asymmetry ``||A - A^T||_inf / ||A||_inf`` above which CG-type methods refuse ``A``.
SYMMETRY_TOL = 1e-10


@dataclass
class Problem:
    """A validated linear system, ready for an iteration."""

    A: Any                      # sparse (CSR), ndarray or LinearOperator
    matvec: Callable[[np.ndarray], np.ndarray]
    b: np.ndarray
    x: np.ndarray               # a private copy of x0 (or zeros), safe to update in place
    rhs_norm: float
    tolerance: float
    maxiter: int
    n: int
    t_start: float = 0.0        # perf_counter() when validation began (for solve_time)


def _matvec_of(A) -> Callable[[np.ndarray], np.ndarray]:
    if isinstance(A, LinearOperator):
        return A.matvec
    return A.__matmul__


def real_array(x, *, name: str) -> np.ndarray:
    """``x`` as a float64 array; complex or non-numeric data raise :class:`InputError`.

    (A plain ``astype(float64)`` would drop imaginary parts with only a warning: a wrong answer.)
    """
    try:
        arr = np.asarray(x)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name} is not a numeric array: {e}") from None
    if np.iscomplexobj(arr):
        raise InputError(f"{name} is complex ({arr.dtype}); femkit's solvers are real (float64): "
                         f"solve real and imaginary parts separately, or use a complex solver")
    if arr.dtype.kind not in "biuf":
        raise InputError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    return np.asarray(arr, dtype=np.float64)


def _check_real_dtype(dtype, name: str) -> None:
    dtype = np.dtype(dtype)
    if dtype.kind == "c":
        raise InputError(f"{name} is complex ({dtype}); femkit's solvers are real (float64)")
    if dtype.kind not in "biuf":
        raise InputError(f"{name} must be numeric, got dtype {dtype}")


def _check_finite_entries(values: np.ndarray, name: str) -> None:
    finite = np.isfinite(values)
    if not finite.all():
        raise InputError(f"{name} has {int(finite.size - np.count_nonzero(finite))} non-finite "
                         f"entries (NaN or inf)")


def as_operator(A, *, name: str = "A"):
    """Return ``A`` as CSR (sparse input), a 2-D float ndarray, or the LinearOperator itself.

    Raises :class:`InputError` for anything else, a non-square shape, complex or
    non-numeric entries, or non-finite entries of an explicit matrix.
    """
    if sp.issparse(A):
        if A.ndim != 2 or A.shape[0] != A.shape[1]:
            raise InputError(f"{name} must be square, got shape {A.shape}")
        _check_real_dtype(A.dtype, name)
        A = A.tocsr()
        if A.dtype != np.float64:
            A = A.astype(np.float64)
        _check_finite_entries(A.data, name)
        return A
    if isinstance(A, LinearOperator):
        if A.shape[0] != A.shape[1]:
            raise InputError(f"{name} must be square, got shape {A.shape}")
        if A.dtype is not None and np.dtype(A.dtype).kind == "c":
            raise InputError(f"{name} is a complex LinearOperator ({A.dtype}); femkit's solvers "
                             f"are real (float64)")
        return A
    if isinstance(A, np.ndarray):
        if A.ndim != 2 or A.shape[0] != A.shape[1]:
            raise InputError(f"{name} must be a square matrix, got shape {A.shape}")
        A = real_array(A, name=name)
        _check_finite_entries(A, name)
        return A
    raise InputError(
        f"{name} must be a scipy.sparse matrix, a 2-D numpy array or a "
        f"scipy.sparse.linalg.LinearOperator, got {type(A).__name__}"
    )


def explicit_csr(A, *, what: str) -> sp.csr_matrix:
    """A validated sparse or dense matrix as float64 CSR; a LinearOperator raises
    :class:`InputError` (``what`` needs the entries)."""
    A = as_operator(A)
    if isinstance(A, LinearOperator):
        raise InputError(f"{what} needs an explicit matrix (sparse or dense), got a "
                         f"{type(A).__name__}")
    return sp.csr_matrix(A) if not sp.issparse(A) else A


def check_options(fn: Callable, options: dict, *, what: str, exclude=()) -> None:
    """Raise :class:`InputError` naming every key of ``options`` that ``fn`` does not take as a
    keyword (so a misspelt option is an error, not a Python ``TypeError`` or silently ignored).
    Functions with ``**kwargs`` are not checked here (they validate their own).

    A function may also declare ``fn.option_choices = {name: (kind, valid_values)}``: a value
    outside ``valid_values`` is then an :class:`~femkit.errors.UnknownNameError` at load time
    (e.g. ``options: {engine: mumps}`` of the ``cholesky`` solver), before any mesh is built."""
    import inspect

    from ..errors import UnknownNameError

    for name, (kind, valid_values) in getattr(fn, "option_choices", {}).items():
        if name in options and options[name] not in valid_values:
            raise UnknownNameError(kind, str(options[name]), list(valid_values))
    params = inspect.signature(fn).parameters
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
        return
    valid = sorted(name for name, p in params.items()
                   if p.kind in (inspect.Parameter.KEYWORD_ONLY,
                                 inspect.Parameter.POSITIONAL_OR_KEYWORD)
                   and p.default is not inspect.Parameter.empty and name not in exclude)
    unknown_options(sorted(set(options) - set(valid)), valid, what=what)


def unknown_options(bad, valid, *, what: str) -> None:
    """Raise :class:`InputError` if ``bad`` (option names) is not empty."""
    if bad:
        raise InputError(f"unknown option(s) {', '.join(repr(k) for k in bad)} for {what}; "
                         f"valid options: {', '.join(valid) if valid else 'none'}")


def check_tolerances(rtol: float, atol: float) -> None:
    """Raise :class:`InputError` unless ``rtol, atol >= 0`` are finite and not both zero."""
    from ..validation import finite_nonnegative

    for label, val in (("rtol", rtol), ("atol", atol)):
        finite_nonnegative(val, label)
    if float(rtol) == 0.0 and float(atol) == 0.0:
        raise InputError(
            "rtol and atol are both 0: the stopping rule ||b - A x|| <= 0 cannot be certified "
            "in floating point; give a positive rtol or atol"
        )


def asymmetry(A) -> float:
    """``||A - A^T||_inf / ||A||_inf`` for a sparse or dense matrix (0 for a zero matrix)."""
    if sp.issparse(A):
        D = (A - A.T).tocsr()
        num = float(np.max(np.asarray(abs(D).sum(axis=1)))) if D.nnz else 0.0
        den = float(np.max(np.asarray(abs(A).sum(axis=1)))) if A.nnz else 0.0
    else:
        num = float(np.max(np.abs(A - A.T).sum(axis=1))) if A.size else 0.0
        den = float(np.max(np.abs(A).sum(axis=1))) if A.size else 0.0
    return num / den if den > 0 else 0.0


def check_symmetric(A, *, method: str, tol: float = SYMMETRY_TOL) -> None:
    """Raise :class:`NotSPDError` if an explicit matrix is not symmetric to ``tol``.

    LinearOperators are not checked (that would cost ``n`` products); the per-iteration
    ``p^T A p > 0`` test still guards them.
    """
    if isinstance(A, LinearOperator):
        return
    a = asymmetry(A)
    if a > tol:
        raise NotSPDError(
            f"{method} needs a symmetric positive definite matrix, but A is not symmetric: "
            f"||A - A^T||_inf / ||A||_inf = {a:.3e} > {tol:.0e} "
            f"(use method='direct' or 'jacobi' for nonsymmetric systems, or pass "
            f"check_symmetry=False to skip this check)"
        )


def diagonal_of(A, diagonal=None) -> np.ndarray:
    """The diagonal of ``A`` (``diagonal=`` is required for a LinearOperator)."""
    if diagonal is not None:
        d = real_array(diagonal, name="diagonal").ravel()
        if d.shape != (A.shape[0],):
            raise InputError(f"diagonal has shape {d.shape}, expected ({A.shape[0]},)")
        return d
    if isinstance(A, LinearOperator):
        raise InputError("A is a LinearOperator: pass its diagonal with diagonal=...")
    return np.asarray(A.diagonal(), dtype=np.float64)


def check_positive_diagonal(d: np.ndarray, *, what: str) -> None:
    """Raise :class:`NotSPDError` naming the first rows with a non-positive or non-finite diagonal."""
    bad = np.flatnonzero(~(d > 0) | ~np.isfinite(d))
    if bad.size:
        rows = ", ".join(str(i) for i in bad[:5]) + (" ..." if bad.size > 5 else "")
        raise NotSPDError(
            f"{what} needs a positive diagonal; {bad.size} row(s) have a zero, negative or "
            f"non-finite diagonal entry (rows {rows}; first value {d[bad[0]]!r})"
        )


def prepare(A, b, x0=None, *, rtol: float = DEFAULT_RTOL, atol: float = 0.0, maxiter=None,
            method: str, symmetric: bool = False, check_symmetry: bool = True,
            default_maxiter_factor: int = 10) -> Problem:
    """Validate a system and return a :class:`Problem` (``x`` is a fresh float64 copy)."""
    t_start = time.perf_counter()
    check_tolerances(rtol, atol)
    A = as_operator(A)
    n = A.shape[0]
    b = real_array(b, name="b")
    if b.ndim == 2 and b.shape[1] == 1:
        b = b[:, 0]
    if b.shape != (n,):
        raise InputError(f"b has shape {b.shape}, but A is {A.shape[0]} x {A.shape[1]}")
    if not np.all(np.isfinite(b)):
        bad = np.flatnonzero(~np.isfinite(b))
        raise InputError(f"b has {bad.size} non-finite entries (first at index {bad[0]})")
    if x0 is None:
        x = np.zeros(n)
    else:
        x = np.array(real_array(x0, name="x0"), dtype=np.float64, copy=True).ravel()
        if x.shape != (n,):
            raise InputError(f"x0 has shape {np.shape(x0)}, expected ({n},)")
        if not np.all(np.isfinite(x)):
            raise InputError("x0 has non-finite entries")
    if maxiter is None:
        maxiter = default_maxiter_factor * n
    else:
        if isinstance(maxiter, bool) or not isinstance(maxiter, (int, np.integer)):
            raise InputError(f"maxiter must be a non-negative integer, got {maxiter!r}")
        if maxiter < 0:
            raise InputError(f"maxiter must be >= 0, got {maxiter}")
        maxiter = int(maxiter)
    if symmetric and check_symmetry:
        check_symmetric(A, method=method)
    rhs_norm = float(np.linalg.norm(b))
    return Problem(A=A, matvec=_matvec_of(A), b=b, x=x, rhs_norm=rhs_norm,
                   tolerance=max(float(rtol) * rhs_norm, float(atol)), maxiter=maxiter, n=n,
                   t_start=t_start)


def as_apply(M, n: int) -> Callable[[np.ndarray], np.ndarray] | None:
    """Turn a preconditioner (callable, LinearOperator, sparse/dense matrix, object with
    ``.matvec``) into a function ``r -> z``; ``None`` stays ``None`` (identity)."""
    if M is None:
        return None
    shape = getattr(M, "shape", None)
    if shape is not None and tuple(shape) != (n, n):
        raise InputError(f"preconditioner M has shape {tuple(shape)}, expected ({n}, {n})")
    if isinstance(M, LinearOperator):
        return M.matvec
    if sp.issparse(M) or isinstance(M, np.ndarray):
        return M.__matmul__
    if hasattr(M, "matvec"):
        return M.matvec
    if callable(M):
        return M
    raise InputError(f"preconditioner M must be callable or have .matvec, got {type(M).__name__}")


def finish(prob: Problem, *, iterations: int, residuals, reason: str, message: str = "",
           method: str, info: dict | None = None, recursive_met: bool = False,
           preconditioner: str = "none") -> SolveResult:
    """Recompute the true residual and build the :class:`SolveResult`.

    ``converged`` is set from the true residual only. If the iteration stopped because its
    recursive residual met the tolerance (``recursive_met``) but the true residual does not,
    the result is ``converged=False, reason="stagnation"`` with a message saying so.
    """
    x = prob.x
    if np.all(np.isfinite(x)):
        true_res = float(np.linalg.norm(prob.b - prob.matvec(x)))
    else:
        true_res = float("nan")
    ok = bool(np.isfinite(true_res) and true_res <= prob.tolerance)
    if recursive_met and not ok:
        reason = "stagnation"
        message = (
            f"recursive residual met the tolerance {prob.tolerance:.3e} after {iterations} "
            f"iterations, but the true residual ||b - A x|| = {true_res:.3e} does not "
            f"(relative {true_res / prob.rhs_norm if prob.rhs_norm else true_res:.3e}): "
            f"rounding errors limit the attainable accuracy; loosen rtol or use a better "
            f"preconditioner/direct solver"
        )
    elif ok and reason in ("converged", ""):
        reason = "converged"
        message = message or (f"true residual {true_res:.3e} <= tolerance {prob.tolerance:.3e} "
                              f"after {iterations} iterations")
    elif reason == "converged" and not ok:  # defensive: never report success the rule denies
        reason = "stagnation"
        message = f"true residual {true_res:.3e} exceeds tolerance {prob.tolerance:.3e}"
    return SolveResult(
        x=x, converged=ok and reason == "converged", iterations=int(iterations),
        residuals=np.asarray(residuals, dtype=np.float64), reason=reason, message=message,
        true_residual=true_res, rhs_norm=prob.rhs_norm, tolerance=prob.tolerance,
        method=method, preconditioner=preconditioner, info=dict(info or {}),
        solve_time=time.perf_counter() - prob.t_start,
    )


def zero_rhs_result(prob: Problem, *, method: str) -> SolveResult:
    """``b = 0``: the solution is ``x = 0`` exactly, converged after 0 iterations.

    ``residuals[0]`` is still the initial residual ``||A x0||`` of the given ``x0``.
    """
    r0 = float(np.linalg.norm(prob.matvec(prob.x))) if np.any(prob.x) else 0.0
    prob.x = np.zeros(prob.n)
    return SolveResult(
        x=prob.x, converged=True, iterations=0, residuals=np.array([r0]), reason="converged",
        message="zero right-hand side: x = 0", true_residual=0.0, rhs_norm=0.0,
        tolerance=prob.tolerance, method=method, solve_time=time.perf_counter() - prob.t_start,
    )


def nonfinite_initial_residual(res: float) -> str:
    """Message for a non-finite initial residual ``||b - A x0||`` (``b`` and ``x0`` are checked
    finite, so the product ``A x0`` is at fault); empty string when ``res`` is finite."""
    if np.isfinite(res):
        return ""
    return (f"the initial residual ||b - A x0|| is {res}: the product A x0 is not finite "
            f"(b and x0 are finite; check the operator); no iteration was run")


def record_iteration(residuals: list, res: float, x: np.ndarray, callback, k: int) -> str:
    """Append ``res`` to the history and call ``callback(x)``; return a non-finite message
    (empty string when ``res`` is finite)."""
    residuals.append(res)
    if callback is not None:
        callback(x)
    return "" if np.isfinite(res) else f"residual became {res} at iteration {k}"
