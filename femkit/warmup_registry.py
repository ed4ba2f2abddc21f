"""The compiled kernels and size thresholds each library module declares for the warm-up.

A library module whose work has a compiled (numba) path registers, where it chooses that path,
the kernels the path calls (:func:`register_kernels`) and the module constants that choose it by
size (:func:`register_threshold`). :mod:`femkit.case.poisson.warmup` reads this registry: it
lowers the registered thresholds while it runs its tiny cases, and a run asks whether every
registered kernel of the families it needs is in numba's on-disk cache
(:func:`femkit.case.poisson.warmup.kernels_cached`). Nothing else keeps a list of the kernels.

A declaration is a few strings: this module imports nothing (not numba, not the kernel modules),
so a module registering its kernels costs its import next to nothing, and reading the registry imports
no kernel.

Examples
--------
>>> from femkit import warmup_registry as w
>>> w.register_kernels("mesh passes", "femkit.mesh._edges_kernel", "cell_edges", rank=0)
>>> ("femkit.mesh._edges_kernel", "cell_edges") in [(k.module, k.name) for k in w.kernels()]
True
"""

from __future__ import annotations

from collections import namedtuple

__all__ = ["Kernel", "register_kernels", "register_threshold", "kernels", "thresholds", "families",
           "COMPILE_MESSAGE"]

#: What every run says before it compiles kernels (the Poisson pipeline's, a solid's energies).
COMPILE_MESSAGE = "compiling kernels (first run, cached afterwards)"


Kernel = namedtuple("Kernel", "family module name tetrahedra_only", defaults=(False,))
Kernel.__doc__ = """One compiled kernel: its ``family`` (the name a run's compile notice says), the dotted
``module`` that defines it and its ``name`` there; ``tetrahedra_only`` when only a run on
tetrahedra calls it."""


_KERNELS: dict[tuple[str, str], Kernel] = {}
_RANKS: dict[str, int] = {}
_THRESHOLDS: dict[tuple[str, str], None] = {}


def register_kernels(family: str, module: str, *names: str, rank: int,
                     tetrahedra_only: bool = False) -> None:
    """Declare the kernels ``names`` of ``module`` (dotted) as members of ``family``.

    ``rank``: where the family comes in the pipeline (families are listed in its order: the mesh
    passes before the assembly ...); every declaration of one family gives the same.
    ``tetrahedra_only``: a run on triangles never calls them. Declaring a kernel again with the
    same values changes nothing (a module reloaded); with others is a ``ValueError``.
    """
    if _RANKS.setdefault(family, rank) != rank:
        raise ValueError(f"kernel family {family!r} declared with ranks {_RANKS[family]} and {rank}")
    for name in names:
        kernel = Kernel(family, module, name, tetrahedra_only)
        if _KERNELS.setdefault((module, name), kernel) != kernel:
            raise ValueError(f"kernel {module}.{name} declared twice, differently")


def register_threshold(module: str, *names: str) -> None:
    """Declare the constants ``names`` of ``module`` (dotted) as size thresholds choosing a
    compiled path: a warm-up sets them to 0 while it runs, so every compiled path is taken."""
    for name in names:
        _THRESHOLDS[(module, name)] = None


def families() -> tuple[str, ...]:
    """The declared kernel families, in pipeline order (their ``rank``)."""
    return tuple(sorted(_RANKS, key=lambda family: _RANKS[family]))


def kernels(names: tuple[str, ...] | None = None) -> tuple[Kernel, ...]:
    """The declared kernels of the families ``names`` (None: all), family by family."""
    chosen = families() if names is None else names
    return tuple(k for family in chosen for k in _KERNELS.values() if k.family == family)


def thresholds() -> tuple[tuple[str, str], ...]:
    """The declared size thresholds, as ``(module, name)`` pairs."""
    return tuple(_THRESHOLDS)
