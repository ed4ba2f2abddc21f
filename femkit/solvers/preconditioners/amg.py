"""Algebraic multigrid preconditioners from pyamg, one V-cycle per application.

``amg_sa`` (smoothed aggregation, ``pyamg.smoothed_aggregation_solver``) and ``amg_rs``
(classical Ruge-Stueben, ``pyamg.ruge_stuben_solver``), built per matrix and applied with
``ml.aspreconditioner(cycle="V")``. The registry alias ``amg`` is smoothed aggregation (the
architecture contract); Ruge-Stueben is the faster peer on 2D Poisson and on stretched
meshes (REFERENCE.md: 6 vs 10 iterations, 6 vs 216 on aspect ratio 1e4), so ask for it by name.
pyamg is imported only inside these functions.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from ...errors import InputError
from .base import Preconditioner


def _wrap(name: str, ml, cycle: str, t0: float) -> Preconditioner:
    M = ml.aspreconditioner(cycle=cycle)
    dt = time.perf_counter() - t0
    info = {
        "levels": len(ml.levels),
        "operator_complexity": float(ml.operator_complexity()),
        "grid_complexity": float(ml.grid_complexity()),
        "cycle": cycle,
        "coarse_size": int(ml.levels[-1].A.shape[0]),
        "hierarchy": ml,
    }
    return Preconditioner(name, M.matvec, ml.levels[0].A.shape[0], dt, info)


def _csr(A):
    if not sp.issparse(A):
        raise InputError("AMG preconditioners need an explicit sparse matrix, "
                         f"got {type(A).__name__}")
    A = sp.csr_matrix(A, dtype=np.float64)
    if A.shape[0] != A.shape[1]:
        raise InputError(f"A must be square, got shape {A.shape}")
    return A


def build_sa(A, *, cycle: str = "V", **opts) -> Preconditioner:
    """Smoothed-aggregation AMG (``pyamg.smoothed_aggregation_solver(A, **opts)``), one cycle."""
    import pyamg

    t0 = time.perf_counter()
    ml = pyamg.smoothed_aggregation_solver(_csr(A), **opts)
    return _wrap("amg_sa", ml, cycle, t0)


def build_rs(A, *, cycle: str = "V", **opts) -> Preconditioner:
    """Ruge-Stueben AMG (``pyamg.ruge_stuben_solver(A, **opts)``), one cycle."""
    import pyamg

    t0 = time.perf_counter()
    ml = pyamg.ruge_stuben_solver(_csr(A), **opts)
    return _wrap("amg_rs", ml, cycle, t0)


#: Default AMG flavour behind the ``amg`` alias.
build = build_sa
