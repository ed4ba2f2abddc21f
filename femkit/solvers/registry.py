"""Solver and preconditioner registries, and :func:`solve`, the high-level entry.

``SOLVERS``: ``jacobi``, ``sd``, ``cg``, ``pcg``, ``direct`` (SuperLU), ``cholesky`` (CHOLMOD,
SPD only), ``fmg``. ``PRECONDITIONERS``: ``none``, ``jacobi``, ``ic0``, ``amg_sa``, ``amg_rs``,
``amg`` (= ``amg_sa``) and ``gmg`` (geometric multigrid; needs ``hierarchy=``). Preconditioner
factories are ``build(A, **opts) -> Preconditioner`` (or ``None`` for ``none``); importing
this module imports neither pyamg nor numba.
"""

from __future__ import annotations

from .defaults import DEFAULT_RTOL, default_preconditioner

import time
from typing import Callable

from ..errors import InputError
from ..registry import Registry
from .cg import cg
from .checks import check_options
from .cholesky import cholesky
from .direct import direct
from .fmg import fmg
from .jacobi import jacobi
from .pcg import pcg
from .preconditioners import amg as _amg
from .preconditioners import gmg as _gmg
from .preconditioners import ic0 as _ic0
from .preconditioners import jacobi as _pjacobi
from .result import SolveResult
from .steepest_descent import steepest_descent

SOLVERS: Registry = Registry("solver")
PRECONDITIONERS: Registry = Registry("preconditioner")

SOLVERS.register("jacobi", jacobi)
SOLVERS.register("sd", steepest_descent)
SOLVERS.register("cg", cg)
SOLVERS.register("pcg", pcg)
SOLVERS.register("direct", direct)
SOLVERS.register("fmg", fmg)
SOLVERS.register("cholesky", cholesky)


def _no_preconditioner(A, **opts):
    """The identity (``M = None``): PCG becomes CG."""
    if opts:
        raise InputError(f"preconditioner 'none' takes no options, got {sorted(opts)}")
    return None


PRECONDITIONERS.register("none", _no_preconditioner)
PRECONDITIONERS.register("jacobi", _pjacobi.build)
PRECONDITIONERS.register("ic0", _ic0.build)
PRECONDITIONERS.register("amg_sa", _amg.build_sa)
PRECONDITIONERS.register("amg_rs", _amg.build_rs)
PRECONDITIONERS.register("amg", _amg.build)
PRECONDITIONERS.register("gmg", _gmg.build)



def get_solver(name: str) -> Callable[..., SolveResult]:
    """The solver function registered as ``name`` (raises :class:`~femkit.errors.UnknownNameError`)."""
    return SOLVERS.get(name)


def get_preconditioner(name: str) -> Callable:
    """The preconditioner factory registered as ``name``."""
    return PRECONDITIONERS.get(name)


def solve(A, b, x0=None, *, method: str = "pcg", preconditioner: str | None = None,
          rtol: float = DEFAULT_RTOL, atol: float = 0.0, maxiter: int | None = None, callback=None,
          preconditioner_options: dict | None = None, backend: str = "femkit",
          **options) -> SolveResult:
    """Solve ``A x = b`` with a registered method and preconditioner, by name.

    Stopping rule of the iterative methods: ``||b - A x|| <= max(rtol ||b||, atol)``,
    with ``converged`` decided on the true residual at exit.

    Parameters
    ----------
    A, b, x0
        The system and initial guess (see the individual methods).
    method : str
        A name in :data:`SOLVERS`.
    preconditioner : str, optional
        A name in :data:`PRECONDITIONERS`; only valid with ``method="pcg"``. ``None`` means
        ``amg`` for ``pcg`` and nothing for the others (:mod:`femkit.solvers.defaults`).
        A preconditioner object/callable may be passed instead of a name (``pcg`` only).
    rtol, atol, maxiter, callback
        As in every method.
    preconditioner_options : dict, optional
        Keyword arguments of the preconditioner factory (e.g. ``{"shift": 1e-2}`` for ic0);
        an unknown name raises :class:`~femkit.errors.InputError` listing the valid ones.
    backend : str
        A name in :data:`femkit.solvers.backend.BACKENDS`: ``femkit`` (these solvers) or
        ``petsc`` (the same names on PETSc KSP/PC, one process; options ``omega``,
        ``petsc_options``; needs petsc4py, else
        :class:`~femkit.errors.BackendUnavailableError`).
    **options
        Method-specific options (``omega`` for jacobi, ``factorization`` for direct ...);
        an unknown name raises :class:`~femkit.errors.InputError` listing the valid ones.

    Returns
    -------
    SolveResult
        With ``method``, ``preconditioner``, ``setup_time`` (building the preconditioner or
        factorisation) and ``solve_time`` (the iterations) filled in.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(20, 20), format="csr")
    >>> r = solve(A, np.ones(20), method="pcg", preconditioner="jacobi")
    >>> r.converged, r.method, r.preconditioner
    (True, 'pcg', 'jacobi')
    """
    if backend != "femkit":
        from .backend import BACKENDS

        factory = BACKENDS.get(backend)
        if preconditioner_options:
            raise InputError(f"preconditioner_options are not used by the {backend} backend "
                             f"(pass PETSc options with petsc_options)")
        return factory().solve(A, b, x0, method=method, preconditioner=preconditioner, rtol=rtol,
                               atol=atol, maxiter=maxiter, callback=callback, **options)
    fn = SOLVERS.get(method)
    if "M" in options:
        raise InputError("solve() takes the preconditioner by name (preconditioner=...), not M=")
    check_options(fn, options, what=f"method {method!r}",
                  exclude=("rtol", "atol", "maxiter", "M", "callback"))
    pc_name = "none"
    M = None
    setup = 0.0
    if preconditioner is not None and not isinstance(preconditioner, str):
        if method != "pcg":
            raise InputError(f"a preconditioner is only valid with method 'pcg', not {method!r}")
        M = preconditioner
        pc_name = getattr(M, "name", type(M).__name__)
    else:
        if preconditioner is None:
            preconditioner = default_preconditioner(method)
        factory = PRECONDITIONERS.get(preconditioner)
        if preconditioner != "none" and method != "pcg":
            raise InputError(
                f"preconditioner {preconditioner!r} is only valid with method 'pcg', not "
                f"{method!r} (use method='pcg', or preconditioner=None)")
        if preconditioner_options and preconditioner == "none":
            raise InputError("preconditioner_options given but no preconditioner is used")
        check_options(factory, preconditioner_options or {},
                      what=f"preconditioner {preconditioner!r}")
        t0 = time.perf_counter()
        M = factory(A, **(preconditioner_options or {}))
        setup = time.perf_counter() - t0
        pc_name = preconditioner
    t0 = time.perf_counter()
    if method == "pcg":
        res = fn(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, M=M, callback=callback,
                 **options)
    else:
        res = fn(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, callback=callback, **options)
    elapsed = time.perf_counter() - t0
    res.method = method
    res.preconditioner = pc_name
    if method in ("direct", "cholesky", "fmg"):  # their own setup_time: factorisation, multigrid
        res.solve_time = elapsed - res.setup_time
    else:
        res.setup_time = setup
        res.solve_time = elapsed
    if M is not None and getattr(M, "info", None):
        res.info.setdefault("preconditioner_info",
                            {k: v for k, v in M.info.items() if k not in ("hierarchy", "factor")})
    return res
