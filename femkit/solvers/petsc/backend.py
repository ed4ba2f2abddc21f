"""The PETSc backend: femkit's solver contract on a KSP.

:func:`ksp_solve` solves a (distributed) ``PETSc.Mat`` / ``PETSc.Vec`` system;
:class:`PetscBackend` implements :class:`femkit.solvers.backend.LinearSolverBackend`, also
for a scipy.sparse matrix on one process (what the implicit dynamics integrators hand it).

The stopping rule is femkit's, ``||b - A x|| <= max(rtol ||b||, atol)`` on the
*unpreconditioned* residual (``KSP_NORM_UNPRECONDITIONED``): PETSc's relative test would use
``||b - A x0||``, so femkit sets ``KSP rtol = 0`` and ``KSP atol = max(rtol ||b||, atol)``.
``converged`` is decided on the true residual ``||b - A x||`` recomputed in parallel at exit;
the KSP monitor gives the residual history (``residuals[0]`` the initial residual) and
``KSPConvergedReason`` maps onto ``reason`` (:mod:`.reasons`).
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from ...errors import InputError
from ..core import defaults
from ..core.checks import check_symmetric, check_tolerances, explicit_csr, real_array, unknown_options
from ..core.result import SolveResult
from . import names, options as popts
from .env import require_petsc
from .failure import collective
from .reasons import femkit_reason, reason_name

#: PETSc error codes worth a word in a one-line message (petscerror.h)
PETSC_ERROR_CODES = {55: "out of memory", 56: "not supported", 62: "invalid argument",
                     63: "argument out of range", 71: "zero pivot", 73: "object in wrong state",
                     76: "error in external library", 86: "unknown type",
                     91: "argument out of range"}

#: options of ``ksp_solve`` / ``PetscBackend.solve`` beyond the common ones
EXTRA_OPTIONS = ("omega", "petsc_options", "check_symmetry")


def petsc_error(exc, what: str) -> InputError:
    """A one-line :class:`InputError` for a ``PETSc.Error`` raised while doing ``what``."""
    code = getattr(exc, "ierr", None)
    meaning = PETSC_ERROR_CODES.get(code, "")
    return InputError(f"PETSc rejected {what}: error code {code}"
                      f"{' (' + meaning + ')' if meaning else ''}")


def configure(ksp, method: str, preconditioner: str | None, *, table: names.PetscNames,
              omega: float = 1.0, petsc_options: dict | None = None) -> tuple[str, dict, dict]:
    """Set KSP/PC types and the norm from femkit names.

    Returns ``(pc_name, femkit_options, user_options)``: the PETSc options femkit's names
    imply (e.g. ``pc_hypre_type``) and the user's ``petsc_options`` (applied after them, so
    they win), both as PETSc option text; the caller scopes them (:func:`.options.scoped`)
    until after ``KSPSetUp`` and checks the user's were used.
    """
    PETSc = require_petsc()
    ksp_type, pc_name, pc_type, extra = names.resolve(method, preconditioner, table)
    ksp.setType(ksp_type)
    pc = ksp.getPC()
    pc.setType(pc_type)
    if ksp_type == "richardson":  # the damping of weighted Jacobi: x += omega D^-1 r
        extra.setdefault("ksp_richardson_scale", float(omega))
    if ksp_type == "preonly":
        ksp.setNormType(PETSc.KSP.NormType.NONE)
    else:
        ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
    return pc_name, {k: popts.option_text(v) for k, v in extra.items()}, popts.normalise(petsc_options)


def ksp_solve(A, b, x0=None, *, table: names.PetscNames, method: str = "pcg",
              preconditioner: str | None = None, rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
              callback: Callable | None = None, omega: float = 1.0,
              petsc_options: dict | None = None):
    """Solve ``A x = b`` for a PETSc ``Mat``/``Vec`` pair (any communicator).

    Parameters
    ----------
    A : petsc4py.PETSc.Mat
        Symmetric positive definite for ``cg``/``pcg``/``direct`` (MUMPS Cholesky).
    b : petsc4py.PETSc.Vec
    x0 : petsc4py.PETSc.Vec, optional
        Initial guess (zero by default).
    table : PetscNames
        The translation of femkit names, as the solver registry derives it
        (``femkit.solvers.registry.petsc_names()``).
    method, preconditioner : str
        femkit names (:mod:`.names`).
    rtol, atol, maxiter, callback
        As in :func:`femkit.solvers.solve`; ``maxiter`` defaults to ``10 N``; ``callback``
        receives this rank's part of the iterate.
    omega : float
        Damping of ``method="jacobi"`` (Richardson scale).
    petsc_options : dict, optional
        Extra PETSc options (:mod:`.options`), applied after femkit's choices.

    Returns
    -------
    (SolveResult, PETSc.Vec)
        The result (``x`` holds this rank's owned part as a numpy copy; ``info`` has the KSP
        and PC types actually used, PETSc's reason name and the number of ranks) and the
        solution vector.

    Raises
    ------
    InputError
        A PETSc option rejected or unused, bad tolerances.
    UnknownNameError
        A method or preconditioner the PETSc backend does not offer.
    """
    PETSc = require_petsc()
    rtol, atol = defaults.tolerances(rtol, atol)
    check_tolerances(rtol, atol)
    t_start = time.perf_counter()
    comm = A.getComm()
    N = A.getSize()[0]
    if maxiter is None:
        maxiter = 10 * max(N, 1)
    if int(maxiter) < 0:
        raise InputError(f"maxiter must be >= 0, got {maxiter}")
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    pc_name, extra, user = configure(ksp, method, preconditioner, table=table, omega=omega,
                                     petsc_options=petsc_options)
    prefix = popts.new_prefix()
    ksp.setOptionsPrefix(prefix)
    bnorm = b.norm()
    tol = max(rtol * bnorm, atol)
    ksp.setTolerances(rtol=0.0, atol=tol if tol > 0 else 1e-300, max_it=int(maxiter))
    x = x0.copy() if x0 is not None else b.duplicate()
    if x0 is None:
        x.zeroEntries()
    else:
        ksp.setInitialGuessNonzero(True)
    history: list[float] = []

    def monitor(_ksp, its, rnorm):
        history.append(float(rnorm))
        if callback is not None and its > 0:
            callback(_ksp.buildSolution().getArray().copy())

    ksp.setMonitor(monitor)
    what = f"the solver set-up ({method}/{pc_name}{', petsc_options ' + ', '.join(user) if user else ''})"
    mpi = comm.tompi4py()

    def from_options():
        try:
            ksp.setFromOptions()
        except PETSc.Error as exc:
            raise petsc_error(exc, what) from exc

    with popts.scoped(prefix, {**extra, **user}):
        # reading the options fails alike on every rank: raised on all, no MPI_Abort needed
        collective(mpi, from_options)
        try:
            t0 = time.perf_counter()
            ksp.setUp()
            setup = time.perf_counter() - t0
        except PETSc.Error as exc:
            raise petsc_error(exc, what) from exc
        collective(mpi, popts.check_used, prefix, user)
        t0 = time.perf_counter()
        # b = 0 decided by its entries (max |b_i|), not by a 2-norm that may underflow
        # (max and min, collective: the infinity norm of Debian's petsc4py 3.18 proved unreliable)
        if max(abs(b.max()[1]), abs(b.min()[1])) == 0.0 and x0 is None:
            its, code = 0, None
        else:
            try:
                ksp.solve(b, x)
            except PETSc.Error as exc:
                raise petsc_error(exc, f"the solve ({method}/{pc_name})") from exc
            its, code = ksp.getIterationNumber(), ksp.getConvergedReason()
        solve = time.perf_counter() - t0
    r = b.duplicate()
    A.mult(x, r)
    r.aypx(-1.0, b)  # r = b - A x
    true_res = r.norm()
    ok = bool(np.isfinite(true_res) and true_res <= tol)
    name = "CONVERGED_ATOL" if code is None else reason_name(PETSc, code)
    reason = femkit_reason(name)
    if method == "direct":  # as femkit's direct: 0 iterations, the initial residual only
        reason, its, history = "direct", 0, history[:1]
    elif reason == "converged" and not ok:
        reason = "stagnation"
    if not history:
        history = [float(bnorm if x0 is None else true_res)]
    message = (f"KSP {ksp.getType()}/{ksp.getPC().getType()} stopped with {name} after {its} "
               f"iterations; true residual {true_res:.3e} "
               f"{'<=' if ok else '>'} tolerance {tol:.3e}")
    pc = ksp.getPC()
    info = {"backend": "petsc", "ranks": comm.getSize(), "ksp_type": ksp.getType(),
            "pc_type": pc.getType(), "ksp_reason": name,
            "petsc_version": ".".join(map(str, PETSc.Sys.getVersion()))}
    if pc.getType() == "hypre":
        info["pc_hypre_type"] = pc.getHYPREType() if hasattr(pc, "getHYPREType") else "boomeramg"
    if pc.getType() in ("cholesky", "lu"):
        info["factor_solver_type"] = pc.getFactorSolverType()
    res = SolveResult(
        x=x.getArray().copy(), converged=ok and reason in ("converged", "direct"),
        iterations=int(its), residuals=np.asarray(history, dtype=np.float64), reason=reason,
        message=message, true_residual=float(true_res), rhs_norm=float(bnorm), tolerance=tol,
        method=method, preconditioner=pc_name, setup_time=setup, solve_time=solve, info=info)
    res.info["total_time"] = time.perf_counter() - t_start
    ksp.destroy()
    r.destroy()
    return res, x


class PetscBackend:
    """:class:`~femkit.solvers.backend.LinearSolverBackend` on PETSc (KSP/PC by femkit name).

    ``solve(A, b)`` takes a ``PETSc.Mat``/``PETSc.Vec`` (distributed; ``x`` of the result is
    this rank's part) or a scipy.sparse matrix and numpy vector (solved on one process,
    ``PETSc.COMM_SELF``; ``x`` is the whole solution), e.g.
    ``BACKENDS.get("petsc")().solve(A, b, method="pcg", preconditioner="amg", rtol=1e-10)``.

    Parameters
    ----------
    table : PetscNames
        The femkit-name translation the solver registry derives from its entries' traits.
    """

    name = "petsc"

    def __init__(self, table: names.PetscNames):
        self.table = table

    def methods(self) -> list[str]:
        return sorted(self.table.methods)

    def preconditioners(self) -> list[str]:
        return sorted(self.table.preconditioners)

    def solve(self, A, b, x0=None, *, method: str = "pcg", preconditioner: str | None = None,
              rtol: float | None = None, atol: float | None = None, maxiter: int | None = None,
              callback: Callable | None = None, **options) -> SolveResult:
        """Same contract as :func:`femkit.solvers.solve`; extra options ``omega`` (jacobi),
        ``petsc_options`` (dict) and ``check_symmetry`` (bool, scipy input)."""
        rtol, atol = defaults.tolerances(rtol, atol)
        unknown_options(sorted(set(options) - set(EXTRA_OPTIONS)), list(EXTRA_OPTIONS),
                        what="the petsc backend")
        check_symmetry = options.pop("check_symmetry", True)
        PETSc = require_petsc()
        if isinstance(A, PETSc.Mat):
            return ksp_solve(A, b, x0, table=self.table, method=method,
                             preconditioner=preconditioner, rtol=rtol,
                             atol=atol, maxiter=maxiter, callback=callback, **options)[0]
        names.resolve(method, preconditioner, self.table)  # names first: a bad name is the clearest error
        A = explicit_csr(A, what="the petsc backend")
        n = A.shape[0]
        b = real_array(b, name="b").ravel()
        if b.shape != (n,):
            raise InputError(f"b has shape {b.shape}, expected ({n},)")
        if check_symmetry and method in self.table.symmetric:
            check_symmetric(A, method=method)
        Ap = as_petsc_matrix(A, PETSc.COMM_SELF)
        bp = PETSc.Vec().createWithArray(b.copy(), comm=PETSc.COMM_SELF)
        xp = None
        if x0 is not None:
            x0 = real_array(x0, name="x0").ravel()
            if x0.shape != (n,):
                raise InputError(f"x0 has shape {x0.shape}, expected ({n},)")
            xp = PETSc.Vec().createWithArray(x0.copy(), comm=PETSc.COMM_SELF)
        res, x = ksp_solve(Ap, bp, xp, table=self.table, method=method,
                           preconditioner=preconditioner, rtol=rtol,
                           atol=atol, maxiter=maxiter, callback=callback, **options)
        for obj in (Ap, bp, x) + ((xp,) if xp is not None else ()):
            obj.destroy()
        return res


def as_petsc_matrix(A, comm):
    """A scipy CSR matrix as a sequential PETSc AIJ matrix on ``comm`` (one process)."""
    PETSc = require_petsc()
    A = A.tocsr()
    A.sort_indices()
    M = PETSc.Mat().createAIJ(size=A.shape, csr=(A.indptr.astype(PETSc.IntType),
                                                 A.indices.astype(PETSc.IntType),
                                                 np.ascontiguousarray(A.data, dtype=np.float64)),
                              comm=comm)
    if A.shape[0]:
        M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return M
