"""Compile the Poisson pipeline's kernels ahead: ``femkit warmup``, or the first large run.

femkit's compiled kernels (numba, ``cache=True``: assembly, edges, geometric multigrid) are
compiled on their first call after an install and loaded from the on-disk cache afterwards. A
first solve would otherwise pay that compile (tens of seconds on a loaded machine) inside its
assembly and solve stages. :func:`warm_up` compiles them on a tiny fmg problem instead, with the
size thresholds that choose the compiled paths lowered for its duration, so every kernel and
every argument type a large run uses is in the cache afterwards; :func:`kernels_cached` says
whether that already happened (the run prints ``compiling kernels (first run, cached
afterwards)...`` and books the time as its own ``compile`` stage when not).
"""

from __future__ import annotations

import importlib
import time
from typing import Callable

__all__ = ["warm_up", "kernels_cached", "needs_kernels", "must_compile", "COMPILE_MESSAGE"]

COMPILE_MESSAGE = "compiling kernels (first run, cached afterwards)..."

#: (module, name) of one kernel of each compiled family; when all are in the on-disk cache the
#: kernels were compiled before (a warm-up compiles every family at once).
_PROBES = (("femkit.fem._kernels", "_pattern"), ("femkit.fem._kernels", "_stiffness"),
           ("femkit.mesh._edges_kernel", "unique_edges"),
           ("femkit.solvers.preconditioners._gmg_kernels", "galerkin"),
           ("femkit.solvers.preconditioners._gmg_kernels", "gs_sweeps"),
           ("femkit.solvers._check_kernels", "asymmetry_sums"))

#: The module constants that choose the compiled paths by size (lowered during a warm-up).
_THRESHOLDS = (("femkit.fem.sparsity", "NUMBA_THRESHOLD"), ("femkit.fem.p1_stiffness", "NUMBA_THRESHOLD"),
               ("femkit.fem.load", "NUMBA_THRESHOLD"), ("femkit.mesh.edges", "NUMBA_THRESHOLD"),
               ("femkit.solvers.checks", "SYMMETRY_NUMBA_NNZ"))

_TINY = {
    "problem": "poisson", "name": "warmup",
    "mesh": {"geometry": "unit_square", "h": 0.25, "refine": 2},
    "source": "2 * pi**2 * sin(pi * x) * sin(pi * y)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": 0}]},
    "exact": {"u": "sin(pi * x) * sin(pi * y)",
              "grad": ["pi * cos(pi * x) * sin(pi * y)", "pi * sin(pi * x) * cos(pi * y)"]},
    "solver": {"method": "fmg"},
}


def needs_kernels(mesh, multigrid: bool) -> bool:
    """True when a run on ``mesh`` (None: not built yet) calls compiled kernels: a mesh above the
    smallest size threshold, or geometric multigrid (``multigrid``: fmg, or pcg + gmg)."""
    if multigrid:
        return True
    if mesh is None:
        return False
    from ...fem.sparsity import NUMBA_THRESHOLD
    from ...mesh.edges import NUMBA_THRESHOLD as EDGES

    return mesh.n_cells >= min(NUMBA_THRESHOLD, EDGES)


def kernels_cached() -> bool:
    """True when every compiled family is in numba's on-disk cache (``NUMBA_CACHE_DIR`` or the
    package's ``__pycache__``)."""
    import os

    for module, name in _PROBES:
        cache = getattr(importlib.import_module(module), name)._cache
        path = getattr(getattr(cache, "_cache_file", None), "_index_path", None)
        if path is None or not os.path.exists(path):
            return False
    return True


def warm_up(echo: Callable[[str], object] | None = None) -> float:
    """Compile (or load) every kernel of the Poisson pipeline on a tiny fmg problem; seconds taken.

    The compiled paths are forced for its duration (the size thresholds set to 0, restored
    after), and gmg-preconditioned CG runs too, so the argument types of a large run are the
    ones compiled.
    """
    from ..load import case_from_dict

    global _ACTIVE
    if echo is not None:
        echo(COMPILE_MESSAGE)
    t0 = time.perf_counter()
    saved = [(importlib.import_module(m), name) for m, name in _THRESHOLDS]
    values = [getattr(mod, name) for mod, name in saved]
    _ACTIVE = True
    try:
        for mod, name in saved:
            setattr(mod, name, 0)
        for solver in ({"method": "fmg"}, {"method": "pcg", "preconditioner": "gmg"}):
            case = case_from_dict(dict(_TINY, solver=solver))
            case.run(write=False, quiet=True)
    finally:
        _ACTIVE = False
        for (mod, name), value in zip(saved, values):
            setattr(mod, name, value)
    return time.perf_counter() - t0


#: True while :func:`warm_up` runs its tiny cases (which must not warm up again).
_ACTIVE = False


def must_compile(mesh, multigrid: bool) -> bool:
    """True before the first run after an install whose ``mesh`` (with geometric multigrid when
    ``multigrid``) will call kernels that are not compiled yet (not inside a warm-up)."""
    return not _ACTIVE and needs_kernels(mesh, multigrid) and not kernels_cached()
