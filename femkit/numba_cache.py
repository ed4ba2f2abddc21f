"""Loading femkit's cached kernels without numba's compiler registries.

numba's on-disk cache (``cache=True``) keeps each kernel's machine code. Before it loads one,
numba's ``Cache.load_overload`` calls ``BaseContext.refresh``, which imports and installs every
typing and lowering registry its *compiler* uses (``numba.np.arraymath``, ``npyimpl``, the
random, typed-container and polynomial implementations, third-party extensions' entry points):
0.2-0.25 s of every process here, most of numba's start-up after its import, and nothing a
loaded kernel calls. Loaded machine code needs only the symbols it was linked against: the C
helpers and math functions numba registers when it creates its target context, the NRT's
(registered by ``rtsys.initialize``) and the hash secret ``numba.cpython.hashing`` registers
when imported.

:func:`lean_cache_loads` makes the cache of femkit's own kernels (functions defined in the
``femkit`` package or in the modules it generates under :func:`femkit.codegen.cache_dir`) load
after just those, and leaves every other function's load to numba as it is. A kernel that is
not in the cache is compiled by numba's compiler, which refreshes the registries itself first.
It applies only to the numba versions it was checked with (:data:`CHECKED`); with another
numba nothing changes.
"""

from __future__ import annotations

import os

__all__ = ["lean_cache_loads", "CHECKED"]

#: numba versions (major.minor) whose cache loading :func:`lean_cache_loads` was checked with.
CHECKED = ("0.68",)

_INSTALLED = False


def _roots() -> tuple[str, ...]:
    """Directories whose functions are femkit's own: the package and the generated modules."""
    from .codegen import cache_dir

    package = os.path.dirname(os.path.abspath(__file__))
    return tuple(os.path.join(os.path.abspath(p), "") for p in (package, str(cache_dir(""))))


def lean_cache_loads() -> bool:
    """Load femkit's cached kernels without numba's compiler registries (see the module's
    documentation), once per process; True when in effect (numba imported, a checked version),
    False when numba's own loading is kept."""
    global _INSTALLED
    if _INSTALLED:
        return True
    import numba

    if ".".join(numba.__version__.split(".")[:2]) not in CHECKED:
        return False
    try:
        import numba.cpython.hashing  # noqa: F401  (registers the hash secret's symbols)
        from numba.core import caching
        from numba.core.runtime import rtsys

    except ImportError:  # pragma: no cover - a checked version has them
        return False
    parts = ("load_overload", "_load_overload", "_guard_against_spurious_io_errors")
    if not all(hasattr(caching.Cache, name) for name in parts):  # pragma: no cover - as above
        return False
    numba_load = caching.Cache.load_overload
    roots = _roots()

    def load_overload(self, sig, target_context):
        code = getattr(getattr(self, "_py_func", None), "__code__", None)
        path = os.path.abspath(code.co_filename) if code is not None else ""
        if not path.startswith(roots):
            return numba_load(self, sig, target_context)
        rtsys.initialize(target_context)  # the NRT's symbols (once; numba's refresh does it too)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    load_overload.__doc__ = numba_load.__doc__
    caching.Cache.load_overload = load_overload
    _INSTALLED = True
    return True
