"""Error norms and source norms in one compiled pass over the quadrature points.

Evaluated by NumPy, a function given as a callable (an exact solution, its gradient, a source)
costs one array of values per function at every quadrature point of the mesh, and each
integral that needs it evaluates it again. A caller that can compile its functions (the case
layer compiles a case file's expressions, :mod:`femkit.case.compiled_expressions`) hands them
here as :class:`FusedKernels`: numba passes generated from :mod:`.templates` that evaluate every
function at once (common subexpressions shared) over a block of cells' quadrature points, in one
loop LLVM vectorises, and add each value to every integral from that small buffer. The passes are used by :func:`femkit.fem.error_norms`,
:func:`~femkit.fem.energy_error`, the residual estimator and the load vector
(:func:`~femkit.fem.assemble_load`: the source at its rule's points, or the whole one-point
load in one pass) when

- the callables opt in: each has the kernels as its ``fused`` attribute, and the kernels stand
  for exactly these callables (``kernels.exact is exact``, ``kernels.source is f``; the gradient
  callable's ``fused`` is the same kernels);
- the mesh has at least :data:`.kernels.NUMBA_THRESHOLD` cells (a small mesh is not worth a compile) and
  the functions use no coordinate beyond its dimension.

Otherwise, and whenever a pass meets a non-finite value or a degenerate cell, the NumPy path
runs and reports it exactly as before. Results agree with the NumPy path to round-off (the
order of the sums over points and vertices, and ``sin``/``cos``/``exp`` within 2 ulp of NumPy's
where the generated functions inline them; tests/fem/test_fused.py).
"""

from __future__ import annotations

from .kernels import FusedKernels, kernels_for
from .passes import barycentric_load, error_sums, nodal_error, source_norm_sq, source_values

__all__ = ["FusedKernels", "kernels_for", "error_sums", "nodal_error",
           "source_norm_sq", "source_values", "barycentric_load"]
