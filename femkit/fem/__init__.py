"""P1 finite elements for ``-div(kappa grad u) = f``: assembly, boundary conditions, norms.

Every assembly function accepts ``elements=`` (an index array or boolean mask) and returns
global-size objects, so the assemblies of a partition of the elements sum to the full one.
Importing this package imports neither numba nor scikit-fem.
"""

from .coefficients import element_coefficient
from .dirichlet import DirichletSystem, apply_dirichlet, dirichlet_values
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
]
