"""The compiled kernels of a set of functions, as a caller hands them in, and when they apply."""

from __future__ import annotations

from types import ModuleType
from typing import Callable
from ...warmup_registry import register_threshold

#: Cells from which the compiled passes are used (below: the NumPy path, no compile).
NUMBA_THRESHOLD = 100_000
register_threshold(__name__, "NUMBA_THRESHOLD")


class FusedKernels:
    """The fused passes of one set of functions (see :mod:`femkit.fem.fused`).

    Parameters
    ----------
    load : callable () -> module
        Returns the generated module (its passes are those of :mod:`.templates`, with the point
        functions of this set); called once, on first use.
    exact, source : callable or None
        The functions the kernels evaluate as the exact solution and as the source.
    gradient : tuple of callables
        The components of the exact gradient the kernels evaluate (empty: none); a gradient
        callable whose ``fused`` is these kernels stands for them.
    dim : int
        The smallest mesh dimension the functions fit (3 when one of them uses ``z``).
    """

    def __init__(self, load: Callable[[], ModuleType], exact: Callable | None = None,
                 source: Callable | None = None, gradient: tuple = (), dim: int = 2):
        self._load = load
        self._module: ModuleType | None = None
        self.exact = exact
        self.source = source
        self.gradient = tuple(gradient)
        self.n_grad = len(self.gradient)
        self.dim = dim

    @property
    def module(self) -> ModuleType:
        """The generated module (loaded on first use)."""
        if self._module is None:
            self._module = self._load()
        return self._module

    def __getstate__(self):  # a module does not pickle: a copy loads it again when it needs it
        return {**self.__dict__, "_module": None}


def kernels_for(mesh, *, exact: Callable | None = None, grad_exact: Callable | None = None,
                source: Callable | None = None) -> FusedKernels | None:
    """The :class:`FusedKernels` that evaluate exactly the given callables on ``mesh``, or None
    (then the NumPy path runs)."""
    first = exact if exact is not None else source if source is not None else grad_exact
    kernels = getattr(first, "fused", None)
    if not isinstance(kernels, FusedKernels) or mesh.n_cells < NUMBA_THRESHOLD:
        return None
    if kernels.dim > mesh.dim or mesh.dim not in (2, 3):
        return None
    if exact is not None and kernels.exact is not exact:
        return None
    if source is not None and kernels.source is not source:
        return None
    if grad_exact is not None and (getattr(grad_exact, "fused", None) is not kernels
                                   or kernels.n_grad != mesh.dim):
        return None
    return kernels
