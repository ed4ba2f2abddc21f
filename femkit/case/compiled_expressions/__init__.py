"""A case file's expressions compiled: numba source generated from their checked trees.

:mod:`.numba_source` prints a set of expressions as one numba point function (and one over a
block of points) with common subexpressions shared, ``sin``/``cos``/``exp`` as the vectorisable
kernels of :mod:`.elementary`; :mod:`.kernels` puts the point functions of a Poisson case (exact
solution, gradient, source) into a module with the fused quadrature passes of
:mod:`femkit.fem.fused`, cached on disk, and attaches them to the expressions, so the error norms
and the residual estimator visit every quadrature point once, compiled.
"""

from .kernels import case_kernels, expression_kernels, module_text
from .numba_source import block_function, point_function

__all__ = ["block_function", "case_kernels", "expression_kernels", "module_text", "point_function"]
