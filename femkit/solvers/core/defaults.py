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
``newton rtol``        ``1e-10``: Newton's residual tolerance of a static solid
                       (:func:`femkit.solids.solve_static`, a solid file's ``static.rtol``)
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
#: Newton's relative residual tolerance of :func:`femkit.solids.solve_static` when none is given.
NEWTON_RTOL: float = 1e-10


def tolerances(rtol: float | None, atol: float | None) -> tuple[float, float]:
    """``(rtol, atol)`` with None read as this module's default *now* (every solver's signature
    says ``rtol=None, atol=None``, so that a default changed here is the default everywhere).

    >>> tolerances(None, None) == (DEFAULT_RTOL, DEFAULT_ATOL), tolerances(1e-6, 1e-3)
    (True, (1e-06, 0.001))
    """
    return (DEFAULT_RTOL if rtol is None else rtol, DEFAULT_ATOL if atol is None else atol)


def default_preconditioner(method: str) -> str:
    """``amg`` for ``pcg``, ``none`` for every other method.

    >>> default_preconditioner("pcg"), default_preconditioner("cg")
    ('amg', 'none')
    """
    return DEFAULT_PRECONDITIONER if method == "pcg" else "none"
