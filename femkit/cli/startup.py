"""What the ``femkit`` process defers at start-up: numpy submodules every process imports and
no command uses get a lazy loader (:func:`defer_unused_imports`, installed by
:func:`femkit.cli.entry`)."""

from __future__ import annotations

import sys

#: numpy's submodules that no femkit command uses but every process imported: scipy's array-API
#: layer (``scipy._lib.array_api_compat.numpy``, imported by ``scipy.sparse``, ``scipy.linalg``
#: and numba's BLAS check) reads every name of ``numpy.__all__``, and numpy imports a submodule
#: when its name is read: ``numpy.f2py`` (the Fortran wrapper generator, ~0.15 s) and
#: ``numpy.testing`` (``unittest`` with it). (``numpy.ma`` is in use: ``np.unique`` asks it.)
DEFERRED_IMPORTS = ("numpy.f2py", "numpy.testing")


class DeferredFinder:
    """A :data:`sys.meta_path` finder giving the modules of :data:`DEFERRED_IMPORTS` Python's
    :class:`importlib.util.LazyLoader`: importing one makes its module object, executed when
    an attribute of it is first used. Only the command's own process installs it (:func:`femkit.cli.entry`)."""

    def __init__(self, names) -> None:
        self.names = set(names)

    def find_spec(self, name, path=None, target=None):
        if name not in self.names:
            return None
        self.names.discard(name)  # once: the module is in sys.modules from now on
        import importlib.machinery
        import importlib.util

        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        spec.loader = importlib.util.LazyLoader(spec.loader)
        return spec


def defer_unused_imports() -> None:
    """Install :class:`DeferredFinder` (nothing is imported now) unless a module is imported already."""
    if not any(name in sys.modules for name in DEFERRED_IMPORTS):
        sys.meta_path.insert(0, DeferredFinder(DEFERRED_IMPORTS))
