"""The contract a linear-solver backend implements.

femkit's own solvers (:func:`femkit.solvers.solve`) are the reference backend (``femkit``,
:class:`femkit.solvers.registry.FemkitBackend`); ``petsc`` is
:class:`femkit.solvers.petsc.PetscBackend` (imported only when asked for). The names map to
factories in :data:`femkit.solvers.registry.BACKENDS`, the one table of solver names;
``solve(..., backend="petsc")`` uses it.
The PETSc backend maps femkit names onto KSP/PC types (``cg``/``pcg`` -> ``KSPCG``, ``direct``
-> ``KSPPREONLY`` + ``PCLU``/``PCCHOLESKY``, ``jacobi`` -> ``PCJACOBI``, ``ic0`` ->
``PCBJACOBI`` + ``PCICC`` with zero levels, ``amg_sa`` -> ``PCGAMG``, ``amg``/``amg_rs`` ->
``PCHYPRE`` BoomerAMG),
set ``KSPSetTolerances(rtol, atol, maxits)`` with the same unpreconditioned-residual norm
(``KSP_NORM_UNPRECONDITIONED``) so the stopping rule ``||b - A x|| <= max(rtol ||b||, atol)``
matches, and translate ``KSPConvergedReason`` into :data:`femkit.solvers.core.result.REASONS`
(``DIVERGED_INDEFINITE_MAT``/``_PC`` -> ``breakdown``, ``DIVERGED_ITS`` -> ``maxiter``,
``DIVERGED_NANORINF`` -> ``non-finite``, ``DIVERGED_BREAKDOWN`` -> ``breakdown``). It
recomputes the true residual at exit and sets ``converged`` from it.
"""

from __future__ import annotations

from typing import Callable, Protocol, runtime_checkable

import numpy as np

from .core.result import SolveResult


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
              preconditioner: str | None = None, rtol: float | None = None,
              atol: float | None = None, maxiter: int | None = None,
              callback: Callable | None = None, **options) -> SolveResult:
        """Same contract as :func:`femkit.solvers.solve` (``rtol``/``atol`` ``None``: the
        defaults of :mod:`femkit.solvers.core.defaults`); unknown names raise
        :class:`~femkit.errors.UnknownNameError`."""
        ...
