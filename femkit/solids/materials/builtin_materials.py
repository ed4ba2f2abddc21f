"""The built-in materials and their registry ``MATERIALS`` (name -> class)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ...registry import Registry
from ..energy import Energy
from .base import Material, StretchMaterial

__all__ = ["MATERIALS", "LinearElastic", "Corotational", "StVenantKirchhoff",
           "StableNeoHookean", "material"]

MATERIALS: Registry = Registry("material")


def _builtin_classes() -> list:
    classes = [MATERIALS.get(n) for n in MATERIALS.names()]
    return [c for c in classes if getattr(c, "energy_expression", None) is not None]


def _builtin_cached(self) -> bool:
    """Whether the built-ins' generated module and its machine code are in the cache."""
    from ..energy.codegen import module_cached
    from .builtin_kernels import builtin_recipe

    return module_cached(builtin_recipe(_builtin_classes()))


def _builtin_kernels(self):
    """The built-in materials' generated module (:func:`.builtin.builtin_kernels` of the
    registered classes written as energies, in the order of their ``code``)."""
    from .builtin_kernels import builtin_kernels

    return builtin_kernels(_builtin_classes())


def register_material(name: str):
    """Class decorator: register a material class as ``name`` and set its ``name`` attribute
    (the name is written once, here) and, for one written as an energy (``energy_expression``),
    its ``code``: the next number of the generated module's ``stretch_energy`` (1, 2, ... in the
    order of registration; nobody numbers them by hand). A material with no energy keeps the
    ``code`` it declares (the linear material's 0: its own compiled point function)."""

    def decorator(cls):
        cls.name = name
        if getattr(cls, "energy_expression", None) is not None:
            cls.code = len(_builtin_classes()) + 1
        cls.kernels = _builtin_kernels
        cls.kernels_cached = _builtin_cached
        return MATERIALS.register(name, cls)

    return decorator


@register_material("linear")
@dataclass(frozen=True)
class LinearElastic(Material):
    """Small-strain linear elasticity (not rotation invariant)."""

    #: not an energy of the stretches: the compiled point function of the linear frame
    code: ClassVar[int] = 0


@register_material("corotational")
@dataclass(frozen=True)
class Corotational(StretchMaterial):
    """Co-rotational linear elasticity ``mu |F - R|^2 + lam/2 tr(R^T F - I)^2``."""

    energy_expression: ClassVar[Energy] = Energy(
        W="mu*((s1 - 1)**2 + (s2 - 1)**2 + (s3 - 1)**2) + lam/2*(s1 + s2 + s3 - 3)**2")


@register_material("stvk")
@dataclass(frozen=True)
class StVenantKirchhoff(StretchMaterial):
    """St. Venant-Kirchhoff ``mu |E|^2 + lam/2 tr(E)^2`` (softens and collapses in compression)."""

    energy_expression: ClassVar[Energy] = Energy(
        W="mu/4*((s1**2 - 1)**2 + (s2**2 - 1)**2 + (s3**2 - 1)**2)"
          " + lam/8*(s1**2 + s2**2 + s3**2 - 3)**2")


@register_material("stable_neo_hookean")
@dataclass(frozen=True)
class StableNeoHookean(StretchMaterial):
    """Rest-stable neo-Hookean, the log-free form of Smith, de Goes & Kim 2018:
    ``mu/2 (I_C - 3) - mu (J - 1) + (lam + mu)/2 (J - 1)^2``.

    That is Smith et al.'s ``mu/2 (I_C - 3) + lam'/2 (J - alpha)^2`` with ``alpha = 1 + mu / lam'``
    (no stress at rest) and ``lam' = lam + mu`` (its linearisation at rest is linear elasticity
    with ``(mu, lam)``), less the constant ``mu^2 / (2 lam')`` so that ``W(I) = 0``. It is not
    their final energy: their ``- mu/2 log(I_C + 1)`` term, and the re-matched Lamé parameters
    that term needs, are left out. Polynomial in the stretches and ``J = s1 s2 s3``, so finite
    for inverted elements. (B. Smith, F. de Goes, T. Kim, "Stable neo-Hookean flesh
    simulation", ACM Trans. Graph. 37(2), 2018.)
    """

    energy_expression: ClassVar[Energy] = Energy(
        W="mu/2*(s1**2 + s2**2 + s3**2 - 3) - mu*(J - 1) + (lam + mu)/2*(J - 1)**2")


def material(name: str, *, mu: float | None = None, lam: float | None = None,
             E: float | None = None, nu: float | None = None, density: float = 1.0) -> Material:
    """A registered material by name, from ``(mu, lam)`` or ``(E, nu)``.

    >>> material("stvk", E=2.6, nu=0.3).mu
    1.0
    """
    from ...errors import MaterialError

    cls = MATERIALS.get(name)
    if (mu is None) == (E is None) or (mu is None) != (lam is None) or (E is None) != (nu is None):
        raise MaterialError(f"material {name!r}: give either (mu, lam) or (E, nu)")
    if E is not None:
        return cls.from_young(E, nu, density)
    return cls(mu, lam, density)
