"""A KSP kept across many solves with one operator: :class:`KeptKsp`.

The time-dependent kinds solve ``A x = b`` once per step with the same ``A`` (a fixed ``dt``):
the KSP and its preconditioner (MUMPS' Cholesky factor for ``direct``, BoomerAMG's hierarchy
for ``pcg``) are set up once (``KSPSetUp``) and every later solve reuses them; an iterative
solve starts from the caller's guess (the previous step's solution). The stopping rule is
:func:`.backend.ksp_solve`'s: ``||b - A x|| <= max(rtol ||b||, atol)`` on the unpreconditioned
residual (``KSP rtol = 0``, ``atol`` set per right-hand side).
"""

from __future__ import annotations

import time

from ...errors import SolverError
from ..core import defaults
from . import names, options as popts
from .backend import configure, petsc_error
from .env import require_petsc
from .failure import collective
from .reasons import reason_name

__all__ = ["KeptKsp"]


class KeptKsp:
    """One KSP on the (distributed) ``PETSc.Mat`` ``A``, set up once, solved many times.

    Parameters
    ----------
    A : petsc4py.PETSc.Mat
        The operator (symmetric positive definite for ``pcg``/``direct``).
    table : PetscNames
        femkit name translation (``femkit.solvers.registry.petsc_names()``).
    method, preconditioner : str
        femkit names (:mod:`.names`).
    rtol, atol : float, optional
        femkit's stopping rule (defaults of :mod:`femkit.solvers.core.defaults`).
    maxiter : int, optional
        Iteration cap per solve (default ``10 N``).
    petsc_options : dict, optional
        Extra PETSc options, applied after femkit's choices.
    """

    def __init__(self, A, *, table: names.PetscNames, method: str = "pcg",
                 preconditioner: str | None = None, rtol: float | None = None,
                 atol: float | None = None, maxiter: int | None = None,
                 petsc_options: dict | None = None):
        PETSc = require_petsc()
        self.A = A
        self.method = method
        self.rtol, self.atol = defaults.tolerances(rtol, atol)
        comm = A.getComm()
        ksp = PETSc.KSP().create(comm)
        ksp.setOperators(A)
        self.pc_name, extra, user = configure(ksp, method, preconditioner, table=table,
                                              petsc_options=petsc_options)
        prefix = popts.new_prefix()
        ksp.setOptionsPrefix(prefix)
        self.maxiter = int(maxiter if maxiter is not None else 10 * max(A.getSize()[0], 1))
        self.iterative = ksp.getType() != "preonly"
        what = f"the solver set-up ({method}/{self.pc_name})"
        mpi = comm.tompi4py()
        t0 = time.perf_counter()
        with popts.scoped(prefix, {**extra, **user}):
            def from_options():
                try:
                    ksp.setFromOptions()
                except PETSc.Error as exc:
                    raise petsc_error(exc, what) from exc
            collective(mpi, from_options)
            try:
                ksp.setUp()
            except PETSc.Error as exc:
                raise petsc_error(exc, what) from exc
            collective(mpi, popts.check_used, prefix, user)
        if self.iterative:
            ksp.setInitialGuessNonzero(True)
        self.setup_seconds = time.perf_counter() - t0
        self.ksp = ksp
        self.solves = 0
        self.iterations = 0
        self._r = A.createVecLeft()

    def solve(self, b, x) -> int:
        """Solve ``A x = b`` in place (``x`` holds the initial guess of an iterative method);
        returns the iterations.

        Raises
        ------
        SolverError
            The true residual misses the tolerance (the KSP's reason named).
        """
        PETSc = require_petsc()
        tol = max(self.rtol * b.norm(), self.atol)
        if self.iterative:
            self.ksp.setTolerances(rtol=0.0, atol=tol if tol > 0 else 1e-300, max_it=self.maxiter)
        try:
            self.ksp.solve(b, x)
        except PETSc.Error as exc:
            raise petsc_error(exc, f"the solve ({self.method}/{self.pc_name})") from exc
        its = int(self.ksp.getIterationNumber()) if self.iterative else 0
        r = self._r
        self.A.mult(x, r)
        r.aypx(-1.0, b)
        res = r.norm()
        # a direct solve is judged at round-off of its factor: 1e-8 ||b|| whatever rtol says
        if not (res <= tol or (not self.iterative and res <= 1e-8 * b.norm())):
            name = reason_name(PETSc, self.ksp.getConvergedReason())
            raise SolverError(f"KSP {self.ksp.getType()}/{self.ksp.getPC().getType()} stopped with "
                              f"{name} after {its} iterations; true residual {res:.3e} > "
                              f"tolerance {tol:.3e}")
        self.solves += 1
        self.iterations += its
        return its

    def destroy(self) -> None:
        """Free the KSP and its work vector."""
        self.ksp.destroy()
        self._r.destroy()
