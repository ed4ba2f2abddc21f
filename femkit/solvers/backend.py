"""The contract a scale-out linear-solver backend implements (design note; no PETSc code).

femkit's own solvers (:func:`femkit.solvers.solve`) are the reference backend. A PETSc
backend would map femkit names onto KSP/PC types (``cg``/``pcg`` -> ``KSPCG``, ``direct``
-> ``KSPPREONLY`` + ``PCLU``/``PCCHOLESKY``, ``jacobi`` -> ``PCJACOBI``, ``ic0`` ->
``PCICC`` with zero levels, ``amg_sa`` -> ``PCGAMG``, ``amg_rs`` -> ``PCHYPRE`` BoomerAMG),
set ``KSPSetTolerances(rtol, atol, maxits)`` with the same unpreconditioned-residual norm
(``KSP_NORM_UNPRECONDITIONED``) so the stopping rule ``||b - A x|| <= max(rtol ||b||, atol)``
matches, and translate ``KSPConvergedReason`` into :data:`femkit.solvers.result.REASONS`
(``DIVERGED_INDEFINITE_MAT``/``_PC`` -> ``breakdown``, ``DIVERGED_ITS`` -> ``maxiter``,
``DIVERGED_NANORINF`` -> ``non-finite``, ``DIVERGED_BREAKDOWN`` -> ``breakdown``). It must
still recompute the true residual at exit and set ``converged`` from it.
"""

from __future__ import annotations

from .defaults import DEFAULT_RTOL

from typing import Callable, Protocol, runtime_checkable

import numpy as np

from .result import SolveResult


@runtime_checkable
class LinearSolverBackend(Protocol):
    """What any backend offers: solve a (possibly distributed) system by method/PC name."""

    name: str

    def methods(self) -> list[str]:
        """Method names understood (a subset of ``femkit.solvers.SOLVERS``)."""
        ...

    def preconditioners(self) -> list[str]:
        """Preconditioner names understood (a subset of ``PRECONDITIONERS``)."""
        ...

    def solve(self, A, b: np.ndarray, x0: np.ndarray | None = None, *, method: str = "pcg",
              preconditioner: str | None = None, rtol: float = DEFAULT_RTOL, atol: float = 0.0,
              maxiter: int | None = None, callback: Callable | None = None,
              **options) -> SolveResult:
        """Same contract as :func:`femkit.solvers.solve`; unknown names raise
        :class:`~femkit.errors.UnknownNameError`."""
        ...


class FemkitBackend:
    """The in-process reference backend (femkit's own solvers)."""

    name = "femkit"

    def methods(self) -> list[str]:
        from .registry import SOLVERS

        return SOLVERS.names()

    def preconditioners(self) -> list[str]:
        from .registry import PRECONDITIONERS

        return PRECONDITIONERS.names()

    def solve(self, A, b, x0=None, **kwargs) -> SolveResult:
        from .registry import solve

        return solve(A, b, x0, **kwargs)
