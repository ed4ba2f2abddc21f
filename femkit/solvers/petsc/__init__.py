"""PETSc + MPI backend (petsc4py): the same solver names and :class:`SolveResult` on a
distributed (or one-process) matrix.

Nothing here imports petsc4py at import time: :func:`require_petsc` does, and raises
:class:`~femkit.errors.BackendUnavailableError` (one line naming ``scripts/install-petsc.sh``)
when it cannot. Modules:

- ``env``: importing petsc4py/mpi4py, the communicator, rank helpers;
- ``names``: femkit method/preconditioner names -> KSP/PC types;
- ``reasons``: ``KSPConvergedReason`` -> :data:`femkit.solvers.core.result.REASONS`;
- ``options``: ``petsc_options`` pass-through (PETSc's options database, per solve prefix);
- ``coo``: ``MatSetPreallocationCOO`` / ``MatSetValuesCOO`` (pattern once, values many);
- ``backend``: :class:`PetscBackend`, the :class:`~femkit.solvers.backend.LinearSolverBackend`;
- ``kept``: :class:`~.kept.KeptKsp`, one KSP set up once and solved for many right-hand sides
  (the time steps of a fixed ``dt``);
- ``failure``: collective error handling (a failing rank never leaves the others hanging).

The distributed Poisson problem (partition, assembly, solve, output) sits one layer up, in
:mod:`femkit.fem.distributed`, and the distributed heat and wave kinds in
``femkit.case.transient.distributed``, since the solver layer knows nothing of meshes.
"""

from .env import INSTALL_HINT, petsc_available, require_petsc

__all__ = ["INSTALL_HINT", "petsc_available", "require_petsc", "PetscBackend"]


def __getattr__(name):  # lazy: importing the package imports no petsc4py
    if name == "PetscBackend":
        from .backend import PetscBackend

        return PetscBackend
    raise AttributeError(name)
