"""Input checks and result assembly shared by every femkit linear solver.

Every method goes through :func:`prepare` (validate ``A``, ``b``, ``x0``, tolerances and
``maxiter``; check symmetry once) and :func:`finish` (recompute the *true* residual and
decide ``converged``), so the stopping rule::

    ||b - A x||_2 <= max(rtol * ||b||_2, atol)

and the error messages are the same for all of them. Norms are scaled 2-norms and ``b = 0`` is
decided by ``b``'s entries (:mod:`femkit.solvers.core.norms`), so the verdict does not change when
``A`` and ``b`` are scaled together.

Tolerance policy: ``rtol`` and ``atol`` must be finite and non-negative, and at least one
of them positive. ``rtol = atol = 0`` asks for an exact solution, which floating-point
iterations cannot certify, so it raises :class:`~femkit.errors.InputError` instead of
silently running to ``maxiter``.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ...errors import InputError, NotSPDError
from .defaults import tolerances
from .norms import binary_exponent, is_zero, norm2
from .result import SolveResult
from ...warmup_registry import register_kernels, register_threshold

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
    b_is_zero: bool = False     # every entry of b is 0 (decided by b, not by its norm)
    exponent: int = 0           # 2^-exponent b has entries of order one (norms.binary_exponent)


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

    from ...errors import UnknownNameError

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
    from ...validation import finite_nonnegative

    for label, val in (("rtol", rtol), ("atol", atol)):
        finite_nonnegative(val, label)
    if float(rtol) == 0.0 and float(atol) == 0.0:
        raise InputError(
            "rtol and atol are both 0: the stopping rule ||b - A x|| <= 0 cannot be certified "
            "in floating point; give a positive rtol or atol"
        )


#: Sparse matrices with at least this many entries are checked by one compiled pass (each
#: row's lower part walked by a pointer: 2-4 SpMV) instead of forming ``A - A^T`` (a
#: transposition and a sparse difference: 15-40 SpMV on a 3D P1 matrix) when numba is loaded
#: already (a compiled assembly or multigrid ran), else from 10x this size: importing numba for
#: the check alone would add ~100 MB to a mid-size run that needs no other kernel.
SYMMETRY_NUMBA_NNZ = 200_000
register_threshold(__name__, "SYMMETRY_NUMBA_NNZ")
register_kernels("solver checks", "femkit.solvers.core._check_kernels", "asymmetry_sums", rank=2)


#: Up to this many rows a sparse matrix is checked as a dense array (a time step's system of a
#: small scene, solved thousands of times: the sparse difference's set-up dominated each solve).
SYMMETRY_DENSE_N = 64


def asymmetry(A) -> float:
    """``||A - A^T||_inf / ||A||_inf`` for a sparse or dense matrix (0 for a zero matrix)."""
    if sp.issparse(A) and A.format == "csr" and A.nnz >= SYMMETRY_NUMBA_NNZ and (
            "numba" in sys.modules or A.nnz >= 10 * SYMMETRY_NUMBA_NNZ):
        from ._check_kernels import asymmetry_sums

        if not A.has_canonical_format:
            A = A.copy()
            A.sum_duplicates()      # sorted, unique indices: what the bisection needs
        num, den = asymmetry_sums(A.indptr, A.indices, A.data)
        return num / den if den > 0 else 0.0
    if sp.issparse(A) and A.shape[0] <= SYMMETRY_DENSE_N:
        A = A.toarray()           # a few dense rows: microseconds, where A - A^T costs ~1 ms
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


def prepare(A, b, x0=None, *, rtol: float | None = None, atol: float | None = None, maxiter=None,
            method: str, symmetric: bool = False, check_symmetry: bool = True,
            default_maxiter_factor: int = 10) -> Problem:
    """Validate a system and return a :class:`Problem` (``x`` is a fresh float64 copy); ``rtol``
    and ``atol`` None are the defaults of :mod:`femkit.solvers.core.defaults` at this call."""
    t_start = time.perf_counter()
    rtol, atol = tolerances(rtol, atol)
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
    rhs_norm = norm2(b)
    return Problem(A=A, matvec=_matvec_of(A), b=b, x=x, rhs_norm=rhs_norm,
                   tolerance=max(float(rtol) * rhs_norm, float(atol)), maxiter=maxiter, n=n,
                   t_start=t_start, b_is_zero=is_zero(b), exponent=binary_exponent(b))


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
    true_res = true_residual(prob, x)
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


def true_residual(prob: Problem, x: np.ndarray) -> float:
    """``||b - A x||_2`` (scaled norm), NaN when ``x`` or the product is not finite."""
    if not np.all(np.isfinite(x)):
        return float("nan")
    with np.errstate(over="ignore", invalid="ignore"):
        r = prob.b - prob.matvec(x)
    if not np.all(np.isfinite(r)):
        return float("nan")
    return norm2(r)


def zero_rhs_result(prob: Problem, *, method: str) -> SolveResult:
    """``b = 0`` (every entry; :attr:`Problem.b_is_zero`): the solution is ``x = 0`` exactly,
    converged after 0 iterations.

    ``residuals[0]`` is still the initial residual ``||A x0||`` of the given ``x0``.
    """
    r0 = norm2(prob.matvec(prob.x)) if np.any(prob.x) else 0.0
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


class Replacement:
    """The normalised system of an iteration with residual replacement (van der Vorst and Ye,
    "Residual replacement strategies for Krylov subspace iterative methods for the convergence
    of true residuals", SIAM J. Sci. Comput. 22(3), 2000).

    The iteration runs on ``b' = 2^-e b``, ``x' = 2^-e x0`` (:mod:`femkit.solvers.core.norms`: exact
    scaling, inner products far from under- and overflow) in *cycles*. Every cycle starts with
    :meth:`start`, which recomputes the true residual ``r = b' - A x'``: the solve is converged
    when it meets the tolerance, stagnant only when it did not decrease since the previous cycle
    start, and otherwise the recursion restarts from it. On stagnation ``x`` goes back to the
    previous cycle start (the smallest true residual), so a restart from the returned ``x``
    repeats the cycle that failed.

    Attributes: ``b``, ``x`` (updated in place by the iteration), ``tol`` (normalised),
    ``residuals`` (normalised history, ``residuals[0]`` the initial residual), ``starts``
    (``(iteration, true residual)`` of every cycle start).
    """

    def __init__(self, prob: Problem):
        from .norms import ldexp_saturating, scaled

        self.prob = prob
        self.e = e = prob.exponent
        self.b = scaled(prob.b, -e)
        with np.errstate(over="ignore"):
            self.x = np.array(scaled(prob.x, -e), dtype=np.float64, copy=True)
        if not np.all(np.isfinite(self.x)):
            raise InputError(f"x0 is more than 2^1000 times larger than b ({norm2(prob.x):.3e} "
                             f"against ||b|| = {prob.rhs_norm:.3e}): start from x0 = 0")
        self.tol = ldexp_saturating(prob.tolerance, -e)
        self.residuals: list[float] = []
        self.starts: list[tuple[int, float]] = []
        self._best = self.x

    def unscaled(self, value: float) -> float:
        """A normalised norm in the units of ``b``."""
        from .norms import unscale

        return unscale(value, self.e)

    def iterate(self) -> np.ndarray:
        """The current iterate in the units of ``x0`` (for callbacks)."""
        from .norms import scaled

        return scaled(self.x, self.e)

    def record(self, res: float, k: int, callback) -> tuple[str, tuple[str, str] | None]:
        """Record the recursive residual norm ``res`` of iteration ``k`` (and call
        ``callback(x)``): ``("met", None)`` when it meets the tolerance (the cycle ends),
        ``("", ("non-finite", message))`` when it is not finite, else ``("", None)``."""
        bad = record_iteration(self.residuals, res, self.iterate() if callback else self.x,
                               callback, k)
        if bad:
            return "", ("non-finite", bad)
        return ("met" if res <= self.tol else ""), None

    def start(self, k: int, *, ended: str = "", window: int = 0):
        """Recompute the true residual at iteration ``k`` and decide: returns ``(r, rr, None)``
        to run a new cycle from ``r`` (``rr = r^T r``), or ``(None, 0, (reason, message))`` to
        stop. ``ended`` says why the previous cycle ended (``"met"``: its recursive residual met
        the tolerance; ``"window"``: no new minimum for ``window`` iterations)."""
        with np.errstate(over="ignore", invalid="ignore"):
            r = self.b - self.prob.matvec(self.x)
        res = norm2(r) if np.all(np.isfinite(r)) else float("nan")
        if not self.residuals:
            self.residuals.append(res)
            bad = nonfinite_initial_residual(res)
            if bad:
                return None, 0.0, ("non-finite", bad)
        elif not np.isfinite(res):
            return None, 0.0, ("non-finite", f"the true residual became {res} at iteration {k}")
        tolerance = self.prob.tolerance
        if res <= self.tol:
            msg = ""
            if len(self.starts) > 1:
                msg = (f"true residual {self.unscaled(res):.3e} <= tolerance {tolerance:.3e} "
                       f"after {k} iterations ({len(self.starts) - 1} residual replacement(s))")
            return None, 0.0, ("converged", msg)
        if self.starts and not res < self.starts[-1][1]:
            k0, res0 = self.starts[-1]
            why = ("the recursive residual met the tolerance" if ended == "met" else
                   f"no residual decrease for {window} iterations")
            self.x = self._best
            return None, 0.0, ("stagnation", (
                f"{why} at iteration {k}, but the true residual ||b - A x|| = "
                f"{self.unscaled(res):.3e} (tolerance {tolerance:.3e}) did not decrease across "
                f"the residual replacement (it was {self.unscaled(res0):.3e} at iteration {k0}, "
                f"the iterate returned): rounding errors limit the attainable accuracy; loosen "
                f"rtol or use a better preconditioner or a direct solver"))
        self.starts.append((k, res))
        self._best = self.x.copy()
        if k >= self.prob.maxiter:
            return None, 0.0, ("maxiter", f"maxiter = {self.prob.maxiter} reached; residual "
                                          f"{self.unscaled(res):.3e} > tolerance {tolerance:.3e}")
        return r, float(np.dot(r, r)), None

    def finish(self, *, iterations: int, reason: str, message: str, method: str,
               info: dict | None = None) -> SolveResult:
        """Back to the units of ``b`` and :func:`finish` (the true residual decides)."""
        from .norms import scaled, unscale_all

        self.prob.x = scaled(self.x, self.e)
        hist = unscale_all(self.residuals, self.e)
        info = {**(info or {}), "residual_replacements": max(len(self.starts) - 1, 0)}
        if reason == "non-finite" and not np.all(np.isfinite(self.prob.x)):
            message += "; the returned x contains non-finite values"
        return finish(self.prob, iterations=iterations, residuals=hist, reason=reason,
                      message=message, method=method, info=info)


#: Top-level packages whose exceptions are caught at the solver boundary and re-raised as femkit
#: errors (:class:`dependency_boundary`); an exception raised in femkit's own code is a bug and
#: passes unchanged.
DEPENDENCIES = ("pyamg", "scipy", "numpy", "sksparse", "petsc4py", "numba", "ctypes")


def raised_in(exc: BaseException) -> str | None:
    """The dependency (a name in :data:`DEPENDENCIES`) whose code raised ``exc``, else None."""
    tb = exc.__traceback__
    last = None
    while tb is not None:
        last, tb = tb, tb.tb_next
    if last is None:
        return None
    top = str(last.tb_frame.f_globals.get("__name__", "")).split(".")[0]
    return top if top in DEPENDENCIES else None


def dependency_error(exc: BaseException, package: str, *, what: str, A=None):
    """The femkit error for ``exc`` raised inside ``package`` while running ``what``:
    :class:`~femkit.errors.NotSPDError` when the explicit matrix ``A`` has a zero, negative or
    non-finite diagonal entry (the dependency broke down on a matrix that is not SPD),
    :class:`~femkit.errors.SingularSystemError` when the dependency says singular, else
    :class:`~femkit.errors.SolverError` (breakdown). The message keeps the dependency's own."""
    from ...errors import SingularSystemError, SolverError

    said = f"{package} raised {type(exc).__name__}: {exc}"
    if A is not None and (sp.issparse(A) or isinstance(A, np.ndarray)) and A.ndim == 2 \
            and A.shape[0] == A.shape[1]:
        d = np.asarray(A.diagonal(), dtype=np.float64)
        bad = np.flatnonzero(~(d > 0) | ~np.isfinite(d))
        if bad.size:
            rows = ", ".join(str(i) for i in bad[:5]) + (" ..." if bad.size > 5 else "")
            return NotSPDError(f"{what} broke down: A is not symmetric positive definite "
                               f"({bad.size} row(s) with a zero, negative or non-finite diagonal "
                               f"entry: {rows}) and {said}")
    if isinstance(exc, np.linalg.LinAlgError) or "singular" in str(exc).lower():
        return SingularSystemError(f"{what}: the system is singular ({said})")
    return SolverError(f"{what} broke down: {said}")


class dependency_boundary:
    """Context manager at a solver's boundary: an exception raised inside a dependency
    (:data:`DEPENDENCIES`) leaves as the femkit error saying what happened
    (:func:`dependency_error`), the dependency's exception kept as its ``__cause__``; femkit
    errors and exceptions of femkit's own code pass unchanged.

    >>> import scipy.sparse as sp
    >>> from femkit.errors import NotSPDError
    >>> try:
    ...     with dependency_boundary("an example", sp.identity(2) * 0):
    ...         import scipy.linalg; scipy.linalg.cholesky([[float("nan")]])
    ... except NotSPDError as e:
    ...     type(e.__cause__).__name__
    'ValueError'
    """

    def __init__(self, what: str, A=None):
        self.what = what
        self.A = A

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        from ...errors import FemkitError

        if exc is None or not isinstance(exc, Exception) or isinstance(exc, FemkitError):
            return False
        package = raised_in(exc)
        if package is None:
            return False
        raise dependency_error(exc, package, what=self.what, A=self.A) from exc
