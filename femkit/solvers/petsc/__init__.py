"""PETSc + MPI backend (petsc4py): the same solver names and :class:`SolveResult` on a
distributed matrix, and a partitioned P1 Poisson assembly.

Nothing here imports petsc4py at import time: :func:`require_petsc` does, and raises
:class:`~femkit.errors.BackendUnavailableError` (one line naming ``scripts/install-petsc.sh``)
when it cannot. Modules:

- ``env``: importing petsc4py/mpi4py, the communicator, rank helpers;
- ``names``: femkit method/preconditioner names -> KSP/PC types;
- ``reasons``: ``KSPConvergedReason`` -> :data:`femkit.solvers.result.REASONS`;
- ``options``: ``petsc_options`` pass-through (PETSc's options database, per solve prefix);
- ``coo``: ``MatSetPreallocationCOO`` / ``MatSetValuesCOO`` (pattern once, values many);
- ``backend``: :class:`PetscBackend`, the :class:`~femkit.solvers.backend.LinearSolverBackend`;
- ``partition``: node partition (PETSc MatPartitioning, PT-Scotch) and contiguous renumbering;
- ``assembly``: each rank assembles its own elements with femkit's kernels into an MPIAIJ matrix;
- ``poisson``: :func:`solve_poisson`, a :class:`~femkit.fem.PoissonProblem` solved on all ranks;
- ``failure``: collective error handling (a failing rank never leaves the others hanging).
"""

from .env import INSTALL_HINT, petsc_available, require_petsc

__all__ = ["INSTALL_HINT", "petsc_available", "require_petsc", "PetscBackend", "solve_poisson"]


def __getattr__(name):  # lazy: importing the package imports no petsc4py
    if name == "PetscBackend":
        from .backend import PetscBackend

        return PetscBackend
    if name == "solve_poisson":
        from .poisson import solve_poisson

        return solve_poisson
    raise AttributeError(name)
