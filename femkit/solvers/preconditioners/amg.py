"""Algebraic multigrid preconditioners from pyamg, one V-cycle per application.

``amg_sa`` (smoothed aggregation, ``pyamg.smoothed_aggregation_solver``) and ``amg_rs``
(classical Ruge-Stueben, ``pyamg.ruge_stuben_solver``), built per matrix and applied as one V-cycle
(:func:`vcycle_apply`: the operations of ``ml.aspreconditioner(cycle="V")`` minus its two
residual-norm evaluations; other cycles, ``cycle="W"``/``"F"``, use ``aspreconditioner``). The registry alias ``amg`` is smoothed aggregation (the
architecture contract); Ruge-Stueben is the faster peer on 2D Poisson and on stretched
meshes (REFERENCE.md: 6 vs 10 iterations, 6 vs 216 on aspect ratio 1e4), so ask for it by name.
pyamg is imported only inside these functions.
"""

from __future__ import annotations

import time

import numpy as np

from ..core.checks import dependency_boundary, explicit_csr, unknown_options
from .base import Preconditioner


def vcycle_apply(ml):
    """``r -> z``: one V-cycle of ``ml`` from a zero initial guess.

    The same operations as pyamg's ``ml.aspreconditioner(cycle="V")`` (pre-smoothing,
    restriction, recursion, coarse solve, prolongation, post-smoothing, from
    ``ml.levels[i].{A, R, P, presmoother, postsmoother}`` and ``ml.coarse_solver``), without
    the two fine-level residual norms pyamg's ``solve(maxiter=1)`` computes for its own
    stopping test: about one fine-grid SpMV less per application.
    """
    levels = ml.levels
    last = len(levels) - 1
    coarse = ml.coarse_solver

    def cycle(lvl, x, b):
        lev = levels[lvl]
        A = lev.A
        lev.presmoother(A, x, b)
        coarse_b = lev.R @ (b - A @ x)
        if lvl == last - 1:
            coarse_x = np.asarray(coarse(levels[-1].A, coarse_b)).ravel()
        else:
            coarse_x = np.zeros_like(coarse_b)
            cycle(lvl + 1, coarse_x, coarse_b)
        x += lev.P @ coarse_x
        lev.postsmoother(A, x, b)

    def apply(r):
        r = np.ascontiguousarray(r, dtype=np.float64).ravel()
        if last == 0:
            return np.asarray(coarse(levels[0].A, r)).ravel()
        z = np.zeros_like(r)
        cycle(0, z, r)
        return z

    return apply


#: State of NumPy's global generator during a pyamg set-up (``RandomState(SETUP_DRAW)``'s;
#: the caller's state is restored afterwards): pyamg draws the
#: start vectors of its spectral-radius estimates (Jacobi prolongation smoothing, smoother
#: weights) from it, so without a fixed state the same matrix gets a different preconditioner, and a
#: different iteration count, on every call.
SETUP_DRAW = 0


def _setup(build, A, what: str, opts: dict):
    """``build(2^-e A, **opts)`` under :data:`SETUP_DRAW` and the solver boundary; returns the
    multilevel solver and ``e``.

    pyamg sees ``A`` normalised to entries of order one (``2^e`` the binary order of its largest
    entry; an exact scaling): LAPACK, behind pyamg's coarse ``pinv``, rescales matrices whose
    norm is below ~1e-138 or above ~1e138 by a factor that is not a power of two, so without it
    the same system in other units got a different preconditioner."""
    from ..core.norms import binary_exponent

    e = binary_exponent(A.data)
    if e:
        A = A.copy()
        A.data = np.ldexp(A.data, -e)
    state = np.random.get_state()
    np.random.set_state(np.random.RandomState(SETUP_DRAW).get_state())
    try:
        with dependency_boundary(what, A):
            return build(A, **opts), e
    finally:
        np.random.set_state(state)


def _wrap(name: str, built, cycle: str, t0: float) -> Preconditioner:
    ml, e = built
    cycle_apply = vcycle_apply(ml) if cycle == "V" else ml.aspreconditioner(cycle=cycle).matvec
    # ml approximates (2^-e A)^-1 = 2^e A^-1
    apply = cycle_apply if e == 0 else (lambda r: np.ldexp(cycle_apply(r), -e))
    dt = time.perf_counter() - t0
    info = {
        "levels": len(ml.levels),
        "operator_complexity": float(ml.operator_complexity()),
        "grid_complexity": float(ml.grid_complexity()),
        "cycle": cycle,
        "coarse_size": int(ml.levels[-1].A.shape[0]),
        "hierarchy": ml,
        "scale_exponent": int(e),
    }
    return Preconditioner(name, apply, ml.levels[0].A.shape[0], dt, info)


def _check_opts(solver, opts: dict, name: str) -> None:
    """Unknown keyword -> :class:`InputError` naming it (pyamg would raise a ``TypeError`` from
    deep inside, or pass it on to ``MultilevelSolver``)."""
    import inspect

    params = inspect.signature(solver).parameters
    valid = sorted({k for k, p in params.items() if k != "A"
                    and p.kind is not inspect.Parameter.VAR_KEYWORD} | {"coarse_solver", "cycle"})
    unknown_options(sorted(set(opts) - set(valid)), valid, what=f"preconditioner {name!r}")


def _csr(A):
    return explicit_csr(A, what="AMG preconditioners")


def build_sa(A, *, cycle: str = "V", **opts) -> Preconditioner:
    """Smoothed-aggregation AMG (``pyamg.smoothed_aggregation_solver(A, **opts)``), one cycle."""
    import pyamg

    _check_opts(pyamg.smoothed_aggregation_solver, opts, "amg_sa")
    t0 = time.perf_counter()
    built = _setup(pyamg.smoothed_aggregation_solver, _csr(A),
                   "preconditioner 'amg_sa' (pyamg set-up)", opts)
    return _wrap("amg_sa", built, cycle, t0)


def build_rs(A, *, cycle: str = "V", **opts) -> Preconditioner:
    """Ruge-Stueben AMG (``pyamg.ruge_stuben_solver(A, **opts)``), one cycle."""
    import pyamg

    _check_opts(pyamg.ruge_stuben_solver, opts, "amg_rs")
    t0 = time.perf_counter()
    built = _setup(pyamg.ruge_stuben_solver, _csr(A), "preconditioner 'amg_rs' (pyamg set-up)",
                   opts)
    return _wrap("amg_rs", built, cycle, t0)


def build(A, *, cycle: str = "V", **opts) -> Preconditioner:
    """``amg``: femkit's default AMG flavour, smoothed aggregation (:func:`build_sa`).

    A function of its own, not the same object as :func:`build_sa`, so that each registered
    name carries its own traits (on PETSc, ``amg`` is BoomerAMG and ``amg_sa`` is GAMG)."""
    return build_sa(A, cycle=cycle, **opts)
