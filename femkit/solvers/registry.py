"""Solver, preconditioner and backend registries, and :func:`solve`, the high-level entry.

``SOLVERS``: ``jacobi``, ``sd``, ``cg``, ``pcg``, ``direct`` (SuperLU), ``cholesky`` (CHOLMOD,
SPD only), ``fmg``. ``PRECONDITIONERS``: ``none``, ``jacobi``, ``ic0``, ``amg_sa``, ``amg_rs``,
``amg`` (= ``amg_sa``) and ``gmg`` (geometric multigrid; needs ``hierarchy=``). Preconditioner
factories are ``build(A, **opts) -> Preconditioner`` (or ``None`` for ``none``); importing
this module imports neither pyamg nor numba. ``BACKENDS``: ``femkit`` (these solvers) and
``petsc`` (:mod:`femkit.solvers.petsc`, imported only when asked for).

Every entry declares what callers need to know about it as :class:`Traits` (``declare``): a
method or preconditioner that works from products ``A d`` alone (``matrix_free``), a method
that reports its own setup time (a factorisation, a multigrid setup). Nothing else in femkit
keeps a list of solver names.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

from ..errors import InputError
from ..registry import Registry
from .core import defaults
from .core.defaults import default_preconditioner
from .core.pairing import PRECONDITIONED_METHOD, check_pairing
from .cg import cg
from .core.checks import check_options
from .cholesky import cholesky
from .direct import direct
from .fmg import fmg
from .jacobi import jacobi
from .pcg import pcg
from .preconditioners import amg as _amg
from . import gmg as _gmg
from .preconditioners import ic0 as _ic0
from .preconditioners import jacobi as _pjacobi
from .core.result import SolveResult
from .petsc.names import MethodSpelling, PetscNames
from .steepest_descent import steepest_descent

SOLVERS: Registry = Registry("solver")
PRECONDITIONERS: Registry = Registry("preconditioner")
BACKENDS: Registry = Registry("solver backend")


@dataclass(frozen=True)
class Traits:
    """What a registered method or preconditioner declares about itself.

    Attributes
    ----------
    matrix_free : bool
        Works from products ``A d`` (and, for a preconditioner, ``diag(A)``) alone, so an
        operator that is never assembled may be solved with it.
    own_setup_time : bool
        The method times its own setup (factorisation, multigrid setup) in ``setup_time``;
        :func:`solve` then reports ``solve_time`` as the rest.
    needs_hierarchy : bool
        Geometric multigrid: the caller passes a :class:`~femkit.mesh.MeshHierarchy`
        (``hierarchy=``, ``free=``) at solve time.
    symmetric : bool
        The method needs a symmetric (positive definite) matrix; the PETSc backend checks a
        scipy matrix for it before solving.
    petsc : object, optional
        How PETSc spells the entry (``None``: the PETSc backend does not offer it): a
        :class:`~femkit.solvers.petsc.names.MethodSpelling` for a method, ``(PC type,
        options)`` for a preconditioner. :func:`petsc_names` gathers them.
    same_as : str, optional
        An alias: the entry builds what the named entry builds (``amg`` is ``amg_sa`` in
        femkit's own solvers), so it is priced as that one (:func:`priced_names`).
    """

    matrix_free: bool = False
    own_setup_time: bool = False
    needs_hierarchy: bool = False
    symmetric: bool = False
    petsc: object = None
    same_as: str | None = None


def declare(entry: Callable, **traits) -> Callable:
    """Attach :class:`Traits` to a solver function or preconditioner factory; returns it."""
    entry.traits = Traits(**traits)
    return entry


def traits(registry: Registry, name: str) -> Traits:
    """The :class:`Traits` of ``name`` in ``registry`` (``SOLVERS`` or ``PRECONDITIONERS``;
    :class:`~femkit.errors.UnknownNameError` for an unknown name)."""
    return getattr(registry.get(name), "traits", Traits())


SOLVERS.register("jacobi", declare(jacobi, petsc=MethodSpelling(  # weighted Jacobi = Richardson
    "richardson", pc_name="jacobi", pc_type="jacobi")))
SOLVERS.register("sd", steepest_descent)
SOLVERS.register("cg", declare(cg, matrix_free=True, symmetric=True, petsc=MethodSpelling("cg")))
SOLVERS.register("pcg", declare(pcg, matrix_free=True, symmetric=True, petsc=MethodSpelling("cg")))
SOLVERS.register("direct", declare(direct, own_setup_time=True, symmetric=True, petsc=MethodSpelling(
    "preonly", pc_name="mumps_cholesky", pc_type="cholesky",  # on PETSc: MUMPS Cholesky
    options={"pc_factor_mat_solver_type": "mumps"})))
SOLVERS.register("fmg", declare(fmg, own_setup_time=True, needs_hierarchy=True))
SOLVERS.register("cholesky", declare(cholesky, own_setup_time=True, symmetric=True))


def _no_preconditioner(A, **opts):
    """The identity (``M = None``): PCG becomes CG."""
    if opts:
        raise InputError(f"preconditioner 'none' takes no options, got {sorted(opts)}")
    return None


_BOOMERAMG = ("hypre", {"pc_hypre_type": "boomeramg"})  # classical Ruge-Stueben AMG
PRECONDITIONERS.register("none", declare(_no_preconditioner, matrix_free=True,
                                         petsc=("none", {})))
PRECONDITIONERS.register("jacobi", declare(_pjacobi.build, matrix_free=True,  # diag(A) only
                                           petsc=("jacobi", {})))
PRECONDITIONERS.register("ic0", declare(_ic0.build, petsc=(  # IC(0) of each rank's block
    "bjacobi", {"sub_pc_type": "icc", "sub_pc_factor_levels": 0, "sub_ksp_type": "preonly"})))
PRECONDITIONERS.register("amg_sa", declare(_amg.build_sa, petsc=("gamg", {"pc_gamg_type": "agg"})))
PRECONDITIONERS.register("amg_rs", declare(_amg.build_rs, petsc=_BOOMERAMG))
PRECONDITIONERS.register("amg", declare(_amg.build, same_as="amg_sa", petsc=_BOOMERAMG))
PRECONDITIONERS.register("gmg", declare(_gmg.build, needs_hierarchy=True))


class FemkitBackend:
    """The in-process reference backend (femkit's own solvers, :func:`solve`)."""

    name = "femkit"

    def methods(self) -> list[str]:
        return SOLVERS.names()

    def preconditioners(self) -> list[str]:
        return PRECONDITIONERS.names()

    def solve(self, A, b, x0=None, **kwargs) -> SolveResult:
        return solve(A, b, x0, **kwargs)


def petsc_names() -> PetscNames:
    """The PETSc translation table, derived from the entries' ``petsc`` and ``symmetric``
    traits (what the PETSc backend and :mod:`femkit.fem.distributed` are handed)."""
    return PetscNames(
        methods={n: traits(SOLVERS, n).petsc for n in SOLVERS.names() if traits(SOLVERS, n).petsc},
        preconditioners={n: traits(PRECONDITIONERS, n).petsc for n in PRECONDITIONERS.names()
                         if traits(PRECONDITIONERS, n).petsc},
        symmetric=frozenset(n for n in SOLVERS.names() if traits(SOLVERS, n).symmetric))


def priced_names(method: str, preconditioner: str | None) -> tuple[str, str | None]:
    """``(method, preconditioner)`` as the cost model's constants name them: the method's
    default preconditioner when none is given, an alias replaced by what it is (``same_as``),
    and no preconditioner for a method that takes none.

    >>> priced_names("pcg", None), priced_names("pcg", "amg"), priced_names("direct", None)
    (('pcg', 'amg_sa'), ('pcg', 'amg_sa'), ('direct', None))
    """
    if preconditioner is None:
        preconditioner = default_preconditioner(method)
    if method != PRECONDITIONED_METHOD:
        return method, None
    if preconditioner in PRECONDITIONERS:
        preconditioner = traits(PRECONDITIONERS, preconditioner).same_as or preconditioner
    return method, preconditioner


def _petsc_backend():
    from .petsc.backend import PetscBackend  # lazy: petsc4py only when asked for

    return PetscBackend(petsc_names())


#: backend name -> factory returning a :class:`~femkit.solvers.backend.LinearSolverBackend`
BACKENDS.register("femkit", FemkitBackend)
BACKENDS.register("petsc", _petsc_backend)


def matrix_free_names() -> tuple[list[str], list[str]]:
    """``(methods, preconditioners)`` declared ``matrix_free`` (preconditioner ``none`` left out)."""
    return ([n for n in SOLVERS.names() if traits(SOLVERS, n).matrix_free],
            [n for n in PRECONDITIONERS.names()
             if n != "none" and traits(PRECONDITIONERS, n).matrix_free])


def lookup(method: str, preconditioner: str | None) -> tuple[Callable, str, Callable]:
    """The one solver-name lookup: ``(solver function, preconditioner name, preconditioner
    factory)`` for the names of a solve (``preconditioner=None``: the method's default).

    Raises
    ------
    UnknownNameError
        Unknown method or preconditioner (``exc.kind`` says which; the valid names are listed).
    InputError
        A preconditioner with a method other than ``pcg`` (:func:`~femkit.solvers.core.pairing.check_pairing`).
    """
    fn = SOLVERS.get(method)
    if preconditioner is None:
        preconditioner = default_preconditioner(method)
    factory = PRECONDITIONERS.get(preconditioner)
    check_pairing(method, preconditioner)
    return fn, preconditioner, factory


def get_solver(name: str) -> Callable[..., SolveResult]:
    """The solver function registered as ``name`` (raises :class:`~femkit.errors.UnknownNameError`)."""
    return SOLVERS.get(name)


def get_preconditioner(name: str) -> Callable:
    """The preconditioner factory registered as ``name``."""
    return PRECONDITIONERS.get(name)


def solve(A, b, x0=None, *, method: str = "pcg", preconditioner: str | None = None,
          rtol: float | None = None, atol: float | None = None, maxiter: int | None = None, callback=None,
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
        ``amg`` for ``pcg`` and nothing for the others (:mod:`femkit.solvers.core.defaults`).
        A preconditioner object/callable may be passed instead of a name (``pcg`` only).
    rtol, atol, maxiter, callback
        As in every method; ``rtol``/``atol`` ``None``: the defaults of
        :mod:`femkit.solvers.core.defaults`, read at call time.
    preconditioner_options : dict, optional
        Keyword arguments of the preconditioner factory (e.g. ``{"shift": 1e-2}`` for ic0);
        an unknown name raises :class:`~femkit.errors.InputError` listing the valid ones.
    backend : str
        A name in :data:`BACKENDS`: ``femkit`` (these solvers) or
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
    rtol, atol = defaults.tolerances(rtol, atol)
    if backend != "femkit":
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
        M = preconditioner
        pc_name = getattr(M, "name", type(M).__name__)
        check_pairing(method, pc_name)
    else:
        _, preconditioner, factory = lookup(method, preconditioner)
        if preconditioner_options and preconditioner == "none":
            raise InputError("preconditioner_options given but no preconditioner is used")
        check_options(factory, preconditioner_options or {},
                      what=f"preconditioner {preconditioner!r}")
        t0 = time.perf_counter()
        M = factory(A, **(preconditioner_options or {}))
        setup = time.perf_counter() - t0
        pc_name = preconditioner
    t0 = time.perf_counter()
    if method == PRECONDITIONED_METHOD:
        res = fn(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, M=M, callback=callback,
                 **options)
    else:
        res = fn(A, b, x0, rtol=rtol, atol=atol, maxiter=maxiter, callback=callback, **options)
    elapsed = time.perf_counter() - t0
    res.method = method
    res.preconditioner = pc_name
    if getattr(fn, "traits", Traits()).own_setup_time:  # factorisation, multigrid setup
        res.solve_time = elapsed - res.setup_time
    else:
        res.setup_time = setup
        res.solve_time = elapsed
    if M is not None and getattr(M, "info", None):
        res.info.setdefault("preconditioner_info",
                            {k: v for k, v in M.info.items() if k not in ("hierarchy", "factor")})
    return res
