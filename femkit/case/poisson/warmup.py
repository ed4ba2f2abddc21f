"""Compile the Poisson pipeline's kernels ahead: ``femkit warmup``, or the first large run.

The kernels and the size thresholds are those the library modules of the pipeline declare
(:mod:`femkit.warmup_registry`, where each chooses its compiled path); nothing here lists them.

femkit's compiled kernels (numba, ``cache=True``: mesh passes, P1 assembly,
solver checks, geometric multigrid, error estimate)
are compiled on their first call after an install and loaded from the on-disk cache afterwards.
A first solve would otherwise pay that compile inside its mesh, assembly and solve stages.
:func:`warm_up` compiles them on a tiny problem instead, with the size thresholds that choose the
compiled paths lowered for its duration, so every kernel and every argument type a large run
uses is in the cache afterwards; :func:`kernels_cached` says whether that already happened (the
run prints ``compiling kernels (first run, cached afterwards): mesh passes, P1 assembly,
geometric multigrid...`` naming what it compiles, books the time as its own ``compile`` stage
and prints how long it took).

Only the families a run needs are compiled (:func:`families`): a run without multigrid compiles
no multigrid kernel. One tiny fmg run compiles every multigrid kernel that pcg + gmg calls too
(the same V-cycle, the same argument types), so the warm-up runs one case, not one per solver.

A case's expressions are compiled too (:mod:`femkit.case.compiled_expressions`, one module per
set of trees): :func:`compile_expressions` does it in the ``compile`` stage of the first run that
meets them on a large mesh, saying so; the warm-up's tiny case has the trees of the bundled fmg
case, so ``femkit warmup`` compiles those.
"""

from __future__ import annotations

import importlib
import time
from typing import Callable

from ...warmup_registry import COMPILE_MESSAGE  # the one wording, shared with solids' energies

__all__ = ["warm_up", "kernels_cached", "dimensions", "needs_kernels", "must_compile", "families", "PIPELINE",
           "MULTIGRID", "COMPILE_MESSAGE", "start_numba", "NUMBA_STAGE"]

#: The kernel family only geometric multigrid calls (a run without it neither needs nor compiles it).
MULTIGRID = "geometric multigrid"

#: The library packages the Poisson pipeline runs on: their modules declare the pipeline's
#: compiled kernels and size thresholds (:mod:`femkit.warmup_registry`) when imported.
PIPELINE = ("femkit.mesh", "femkit.fem", "femkit.fem.fused", "femkit.fem.estimators", "femkit.solvers")


def _registry():
    """:mod:`femkit.warmup_registry` with the pipeline's declarations in it (its packages imported:
    a run has imported them already, so this costs it nothing)."""
    for package in PIPELINE:
        importlib.import_module(package)
    return importlib.import_module("femkit.warmup_registry")


def _thresholds() -> tuple[tuple[str, str], ...]:
    """The declared module constants that choose the compiled paths by size (lowered during a
    warm-up)."""
    return _registry().thresholds()


#: The tetrahedral tiny case (run after :data:`_TINY`): the 3D kernels of the same families
#: (the tetrahedron assembly, the face numbering, the estimator's face jumps); a constant source
#: and no exact solution, so its own expression module is small (the load's source passes).
_TINY_3D = {
    "problem": "poisson", "name": "warmup3d",
    "mesh": {"geometry": "kuhn_cube", "h": 0.5, "refine": 1},
    "source": "1",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
}

_TINY = {
    "problem": "poisson", "name": "warmup",
    "mesh": {"geometry": "unit_square", "h": 0.25, "refine": 2},
    "source": "2 * pi**2 * sin(pi * x) * sin(pi * y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "exact": {"u": "sin(pi * x) * sin(pi * y)",
              "grad": ["pi * cos(pi * x) * sin(pi * y)", "pi * sin(pi * x) * cos(pi * y)"]},
    "solver": {"method": "fmg"},
}


def families(multigrid: bool) -> tuple[str, ...]:
    """The compiled families a run uses: all of them with geometric multigrid, else edges,
    assembly and the error estimate."""
    every = _registry().families()
    return every if multigrid else tuple(f for f in every if f != MULTIGRID)


__all__ += ["compile_expressions", "expressions_cached", "EXPRESSIONS_MESSAGE"]

#: Said when a run compiles its case's expressions (:func:`compile_expressions`).
EXPRESSIONS_MESSAGE = "compiling the case's expressions (first run, cached afterwards)..."


def needs_kernels(mesh, multigrid: bool, element: str = "P1") -> bool:
    """True when a run on ``mesh`` (None: not built yet) with ``element`` calls compiled kernels:
    a mesh above the smallest size threshold (the assembly's is the element's,
    :func:`femkit.fem.sparsity.compiled_from`), or geometric multigrid (``multigrid``: fmg, or
    pcg + gmg)."""
    if multigrid:
        return True
    if mesh is None:
        return False
    from ...elements import get_element
    from ...fem.sparsity import compiled_from
    from ...mesh.edges import NUMBA_THRESHOLD as EDGES

    return mesh.n_cells >= EDGES or compiled_from(mesh.n_cells, get_element(element, mesh.dim))


def dimensions(dim: int | None) -> tuple[int, ...]:
    """The dimensions whose kernels a run on a ``dim``-D mesh compiles (None: unknown, all)."""
    return (2,) if dim == 2 else (2, 3)


def kernels_cached(names: tuple[str, ...] | None = None, dims: tuple[int, ...] = (2, 3)) -> bool:
    """True when every declared kernel (:mod:`femkit.warmup_registry`) of the families ``names``
    (default: all) that a run in the dimensions ``dims`` calls is in numba's on-disk cache
    (``NUMBA_CACHE_DIR`` or the package's ``__pycache__``)."""
    import os

    for kernel in _registry().kernels(names):
        if 3 not in dims and kernel.tetrahedra_only:
            continue
        cache = getattr(importlib.import_module(kernel.module), kernel.name)._cache
        path = getattr(getattr(cache, "_cache_file", None), "_index_path", None)
        if path is None or not os.path.exists(path):
            return False
    return True


def warm_up(echo: Callable[[str], object] | None = None, multigrid: bool = True,
            dims: tuple[int, ...] = (2, 3)) -> float:
    """Compile (or load) the kernels of the Poisson pipeline on two tiny problems (triangles,
    tetrahedra); seconds taken.

    ``multigrid``: the tiny problems run fmg (every family), else pcg + jacobi (edges and
    assembly only). ``dims``: (2,) compiles the triangle run's kernels only (the first run of a
    2D case), (2, 3) the tetrahedra's too (``femkit warmup``, a 3D case). The compiled paths are forced for its duration (the size thresholds set to
    0, restored after), so the argument types of a large run are the ones compiled. ``echo``
    receives one line naming the families compiled.
    """
    from ..load import case_from_dict

    global _ACTIVE
    if echo is not None:
        echo(f"{COMPILE_MESSAGE}: {', '.join(families(multigrid))}...")
    t0 = time.perf_counter()
    saved = [(importlib.import_module(m), name) for m, name in _thresholds()]
    values = [getattr(mod, name) for mod, name in saved]
    _ACTIVE = True
    try:
        for mod, name in saved:
            setattr(mod, name, 0)
        solver = {"method": "fmg"} if multigrid else {"method": "pcg", "preconditioner": "jacobi"}
        for dim, tiny in zip((2, 3), (_TINY, _TINY_3D)[:len(dims)]):  # triangles, tetrahedra
            case = case_from_dict(dict(tiny, solver=solver))
            case.run(write=False, quiet=True)
            _compile_all_passes(case, dim)
        from ...fem._kernels import warm_up as assembly_kernels
        from ...fem._one_off_stiffness import warm_up as one_off_kernels

        one_off_kernels(dims)  # the incidence rows of a mesh read (the tiny case's are refined)

        assembly_kernels()  # the cached-pattern assembly, which a one-off run does not call
        from ...fem._element_kernels import warm_up as element_kernels

        element_kernels()  # P2's pattern, stiffness and load passes
        from ...mesh._refine_kernel import warm_up as refinement_kernels

        refinement_kernels(dims=dims)  # a renumbered (large) hierarchy's, which the tiny cases skip
        from ...fem.estimators._kernels import warm_up as estimator_kernels

        estimator_kernels()  # the estimator's Neumann and area passes, which the tiny case skips
        from ...mesh import generate, quality

        quality(generate("unit_square", 0.5))  # a mesh read or generated (a refined one's numbers
        #                                        come from its root's, without the pass)
        _symmetry_check()   # fmg skips it on the pipeline's matrix; pcg, cg ... do not
    finally:
        _ACTIVE = False
        for (mod, name), value in zip(saved, values):
            setattr(mod, name, value)
    return time.perf_counter() - t0


def _symmetry_check() -> None:
    """The solvers' symmetry check on a system the pipeline's way assembled and reduced (the
    argument types of a large run)."""
    from ...fem import PoissonProblem
    from ...mesh import generate, refine
    from ...solvers.core.checks import check_symmetric

    problem = PoissonProblem(refine(generate("unit_square", 0.5), 1), kappa=1.0, f=1.0,
                             dirichlet=[(["boundary"], 0.0)])
    K, F = problem.assemble_matrices(keep_pattern=False)
    check_symmetric(problem.reduce(K, F, "pcg", overwrite=True).A, method="pcg")


#: True while :func:`warm_up` runs its tiny case (which must not warm up again).
_ACTIVE = False


#: The stage booking numba's start-up (:func:`start_numba`).
NUMBA_STAGE = "numba"

_NUMBA_STARTED = False


def start_numba(stage) -> None:
    """numba's start-up, once per process, in the stage :data:`NUMBA_STAGE` of ``stage`` (a
    :class:`~femkit.timing.StageTimer`): its import (~0.2-0.3 s) and what its first cached
    kernel needs. femkit's cached kernels load without numba's compiler registries
    (:func:`femkit.numba_cache.lean_cache_loads`); with a numba that was not checked for that,
    the registries are loaded here (~0.2-0.6 s: numba's ``BaseContext.refresh``, which imports
    ``numba.np.arraymath``, its BLAS check and the rest). Without this the first kernel called
    paid it inside the stage that called it (the mesh stage's refinement), and the import was
    "other" time. Not inside a warm-up; a numba whose internals differ is only imported (the
    first kernel then loads the registries, as before)."""
    global _NUMBA_STARTED
    if _NUMBA_STARTED or _ACTIVE:
        return
    _NUMBA_STARTED = True
    with stage(NUMBA_STAGE):
        from ...numba_cache import lean_cache_loads

        if lean_cache_loads():
            return
        try:
            from numba.core.registry import cpu_target

            cpu_target.target_context.refresh()
        except Exception:  # pragma: no cover - another numba's layout
            pass


def must_compile(mesh, multigrid: bool, dims: tuple[int, ...] = (2, 3), element: str = "P1") -> bool:
    """True before the first run after an install whose ``mesh`` (with geometric multigrid when
    ``multigrid``; in the dimensions ``dims``; with ``element``) will call kernels that are not
    compiled yet (not inside a warm-up)."""
    return (not _ACTIVE and needs_kernels(mesh, multigrid, element)
            and not kernels_cached(families(multigrid), dims))


def _passes(kernels, dim: int) -> list[str]:
    """The fused passes (:mod:`femkit.fem.fused.templates`) a run on a ``dim``-D mesh calls."""
    names = []
    if kernels.exact is not None:
        names += ["triangle_pass" if dim == 2 else "tetrahedron_pass", "nodal_pass"]
    if kernels.source is not None and (kernels.exact is None or not kernels.module.HAS_SOURCE):
        names.append("source_pass")
    if kernels.source is not None:
        names += ["source_values", "barycentric_load"]  # the load vector (any rule, one-point)
    return names


def expressions_cached(kernels, dim: int) -> bool:
    """True when every fused pass of ``kernels`` a ``dim``-D run calls is in numba's cache."""
    import os

    for name in _passes(kernels, dim):
        cache = getattr(kernels.module, name)._cache
        path = getattr(getattr(cache, "_cache_file", None), "_index_path", None)
        if path is None or not os.path.exists(path):
            return False
    return True


def _compile_all_passes(case, dim: int) -> None:
    """Every fused pass of ``case``'s expressions on a ``dim``-D mesh, not only those its tiny
    run called: a larger run or another load rule calls the others (the one-pass load for the
    centroid rule, the source values for a rule of several points)."""
    from ..compiled_expressions import case_kernels

    kernels = case_kernels(case)
    if kernels is not None and kernels.dim <= dim:
        _compile_passes(kernels, dim)


def _compile_passes(kernels, d: int, cell_type="int64") -> None:
    """Call each pass a run on a ``d``-D mesh calls once, on two cells of the same array types
    (cells of ``cell_type``, a mesh's)."""
    import numpy as np

    from ...fem.quadrature import rule_for_degree

    points = np.vstack([np.zeros(d), np.eye(d), np.ones((1, d))])
    cells = np.array([np.arange(d + 1), np.arange(1, d + 2)], dtype=cell_type)
    rule = rule_for_degree(5, d)
    bary, weights = np.ascontiguousarray(rule.points), np.ascontiguousarray(rule.weights)
    u, out = np.zeros(len(points)), [np.empty(2) for _ in range(3)]
    mod = kernels.module
    for name in _passes(kernels, d):
        if name in ("triangle_pass", "tetrahedron_pass"):
            getattr(mod, name)(points, cells, bary, weights, u, *out)
        elif name == "nodal_pass":
            mod.nodal_pass(points, u)
        elif name == "source_values":
            mod.source_values(points, cells, bary, np.empty((2, len(bary))))
        elif name == "barycentric_load":
            mod.barycentric_load(points, cells, bary[:1], len(points))
        else:
            mod.source_pass(points, cells, bary, weights, np.ones(2), out[0])


def compile_expressions(case, mesh, stage, echo: Callable[[str], object] | None = None) -> None:
    """Give the case's expressions their compiled kernels (:mod:`femkit.case.compiled_expressions`);
    when ``mesh`` is large enough for them and they are not in the cache yet, compile them now in
    the ``compile`` stage, saying so (``echo``)."""
    from ...fem.fused import kernels as fused
    from ..compiled_expressions import case_kernels

    kernels = case_kernels(case)
    if kernels is None or _ACTIVE or mesh.n_cells < fused.NUMBA_THRESHOLD or kernels.dim > mesh.dim:
        return
    if expressions_cached(kernels, mesh.dim):
        return
    with stage("compile"):
        if echo is not None:
            echo(EXPRESSIONS_MESSAGE)
        _compile_passes(kernels, mesh.dim, mesh.cells.dtype)
