"""Finite elements (P1, P2) for ``-div(kappa grad u) = f``: assembly, boundary conditions, norms.

P1 has its own tuned routines (``assemble_stiffness``, ``assemble_load`` ...); any element of
:data:`femkit.elements.ELEMENTS` (P2) goes through :func:`dof_map`, :func:`assemble_matrix`,
:func:`mass_matrix` and :mod:`femkit.fem.lagrange`, on the same pattern stack
(:mod:`femkit.fem.sparsity`); :class:`PoissonProblem` takes ``element=``.

Every assembly function accepts ``elements=`` (an index array or boolean mask) and returns
global-size objects, so the assemblies of a partition of the elements sum to the full one.
Importing this package imports neither numba nor scikit-fem.
"""

from .coefficients import element_coefficient
from .dirichlet import DirichletSystem, apply_dirichlet, dirichlet_values
from .dofs import DofMap, dof_map
from .forms import assemble_matrix
from .mass import mass_matrix
from .load import assemble_load
from .neumann import assemble_neumann
from .norms import energy_error, error_norms
from .p1_stiffness import assemble_stiffness, local_stiffness
from .poisson import PoissonProblem, PoissonSolution
from .quadrature import QUADRATURE, TET_QUADRATURE, TriangleRule, get_rule
from .sparsity import SparsityPattern

__all__ = [
    "assemble_stiffness", "local_stiffness", "assemble_load", "assemble_neumann", "apply_dirichlet",
    "dirichlet_values", "DirichletSystem", "error_norms", "energy_error", "element_coefficient", "PoissonProblem",
    "PoissonSolution", "SparsityPattern", "QUADRATURE", "TET_QUADRATURE", "TriangleRule", "get_rule",
    "DofMap", "dof_map", "assemble_matrix", "mass_matrix",
]
