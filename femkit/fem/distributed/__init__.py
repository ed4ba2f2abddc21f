"""Distributed P1 Poisson assembly and solve on PETSc + MPI (the scale-out path).

Every rank holds the mesh (read or generated once on rank 0 and broadcast), owns a contiguous
block of renumbered nodes (:mod:`.partition`), assembles its own elements with femkit's kernels
into a PETSc MPIAIJ matrix (:mod:`.assembly`) and solves with the PETSc backend
(:mod:`femkit.solvers.petsc`) by femkit's solver names (:mod:`.poisson`); large solutions are
written as parallel VTK (:mod:`.pvtu`). Importing this package imports no petsc4py.
"""

__all__ = ["solve_poisson", "broadcast_mesh"]


def __getattr__(name):  # lazy: petsc4py only when used
    if name in __all__:
        from . import poisson

        return getattr(poisson, name)
    raise AttributeError(name)
