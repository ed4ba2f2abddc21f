"""Linear solvers: femkit's own Jacobi, steepest descent, CG and PCG, a SuperLU direct
solver, a sparse Cholesky (CHOLMOD) for SPD systems, and Jacobi / IC(0) / AMG preconditioners, selectable by name.

>>> import numpy as np, scipy.sparse as sp
>>> from femkit.solvers import solve
>>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(10, 10), format="csr")
>>> solve(A, np.ones(10), method="cg").converged
True

Importing this package imports numpy and scipy only (pyamg and numba load on first use).

Layout (no import cycle between these folders): :mod:`femkit.solvers.core` (defaults, results,
checks, norms, pairing) below everything; :mod:`femkit.solvers.preconditioners` and
:mod:`femkit.solvers.petsc` on it; the solver modules of this folder (and :mod:`.gmg`, geometric
multigrid, which factorises its coarsest level through :mod:`.kept_factor`) on top, with the registry.
``femkit.solvers.defaults`` is :mod:`femkit.solvers.core.defaults` (the one table of defaults).
"""

from .backend import LinearSolverBackend
from .core import defaults
from .cg import cg
from .cholesky import CholeskyFactor, cholesky, factorize_spd
from .direct import direct, factorize
from .factor import Factor
from .jacobi import jacobi
from .pcg import pcg
from .preconditioners.base import Preconditioner
from .registry import (BACKENDS, PRECONDITIONERS, SOLVERS, FemkitBackend, get_preconditioner,
                       get_solver, solve)
from .core.result import REASONS, SolveResult
from .session import LinearSession
from .spec import SolverSpec
from .steepest_descent import steepest_descent

__all__ = [
    "BACKENDS", "PRECONDITIONERS", "SOLVERS", "REASONS", "CholeskyFactor", "Factor", "FemkitBackend",
    "LinearSession", "LinearSolverBackend", "Preconditioner", "SolveResult", "SolverSpec", "cg", "cholesky",
    "direct", "factorize_spd",
    "factorize", "get_preconditioner", "get_solver", "jacobi", "pcg", "solve",
    "steepest_descent",
]
