"""The one table of solver defaults, read by :func:`femkit.solvers.solve`, every method's
signature and the application layer's solver spec (case files, scenes, studies).

=====================  ===========================================================
key                    default
=====================  ===========================================================
``rtol``               ``1e-10``: relative tolerance of ``||b - A x|| <= max(rtol ||b||, atol)``
``atol``               ``0.0``
``maxiter``            ``None``: each method's own bound (e.g. ``10 n`` for CG)
``preconditioner``     ``amg`` for ``pcg`` (smoothed aggregation), ``none`` otherwise
``method``             per kind of file, declared by the kind itself
                       (:attr:`femkit.kinds.Kind.default_solver`): ``pcg`` for Poisson,
                       ``direct`` for scenes, solids and the cloth study
``engine``             ``cholmod``: the factorisation library of ``cholesky``
``comparison rtol``    ``1e-8``: the solvers a study compares by cost (adaptive,
                       stability) stop here unless the study file names its own
=====================  ===========================================================

docs/case-files.md documents the same table for users.
"""

from __future__ import annotations

#: Relative tolerance of every iterative method when none is given.
DEFAULT_RTOL: float = 1e-10
#: Absolute tolerance when none is given.
DEFAULT_ATOL: float = 0.0
#: Preconditioner of ``pcg`` when none is named (other methods take none).
DEFAULT_PRECONDITIONER: str = "amg"
#: Factorisation library of the ``cholesky`` method (``options: {engine}``).
DEFAULT_ENGINE: str = "cholmod"
#: Relative tolerance of the default solver lists of the studies that compare solvers' cost.
COMPARISON_RTOL: float = 1e-8


def default_preconditioner(method: str) -> str:
    """``amg`` for ``pcg``, ``none`` for every other method.

    >>> default_preconditioner("pcg"), default_preconditioner("cg")
    ('amg', 'none')
    """
    return DEFAULT_PRECONDITIONER if method == "pcg" else "none"
