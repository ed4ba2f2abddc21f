"""What a material is: a small frozen record of its constants plus one compiled energy function.

A hyperelastic isotropic material is fully described by its energy density as a function of the
principal stretches ``W(s_1, .., s_d)`` (Xu, Sin, Zhu & Barbic 2015); forces and Hessians then
follow from the SVD derivative (:mod:`femkit.elements.compiled`) with only ``dW/ds`` and
``d^2W/ds^2``. So a material here *is* that function and its constants:

* :class:`StretchMaterial` subclasses carry that function as an expression: the built-ins
  (:mod:`.builtin_materials`) as ``energy_expression``, a material designed by a user (:mod:`.designed`)
  as its ``energy``. Derivatives are generated symbolically and compiled into numba kernels by
  one path (:mod:`femkit.solids.energy.codegen`; the built-ins share one module,
  :mod:`.builtin_kernels`); the material names its energy there by number, ``code``, and the element
  kernels (SVD, SVD derivative, projection, assembly: :mod:`femkit.elements.compiled`) are shared.
* The linear (small-strain) material is not a function of the stretches (not rotation
  invariant); its point function of ``F`` is :func:`femkit.elements.compiled._linear_frame`
  (``code`` 0).

Constants are the Lame moduli ``mu``, ``lam`` of the material *linearised at rest*: at ``F = I``
every material's Hessian is the linear-elasticity tensor with these moduli. Plane strain in 2D:
the same formulas with ``d = 2`` stretches (the third is 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...errors import MaterialError

__all__ = ["Material", "StretchMaterial", "lame_from_young", "MAX_MODULUS"]

#: Largest size of a modulus (``E``, ``mu``, ``lam``) and of a density: the energy, its
#: derivatives and the checks multiply up to three of them (``mu * lam``, ``E * I``, ...), which
#: must stay finite in double precision (about 1.8e308). Physical moduli are below 1e13 Pa.
#: Its reciprocal is the smallest positive modulus and density (below it the same products
#: underflow to zero). An energy's constants are bounded alike.
MAX_MODULUS = 1e100


def _bounded(value: float, name: str) -> float:
    if abs(value) > MAX_MODULUS:
        raise MaterialError(f"{name} = {value:g} is larger than {MAX_MODULUS:g}: products of "
                            "the moduli (mu * lam, the energy's derivatives) would overflow; "
                            "choose units that make it smaller")
    return value


def _finite(value, name: str) -> float:
    """``value`` as a float, refused unless finite and at most :data:`MAX_MODULUS` in size.

    >>> _finite(1e300, "constant k")
    Traceback (most recent call last):
    ...
    femkit.errors.MaterialError: constant k = 1e+300 is larger than 1e+100: products of the moduli (mu * lam, the energy's derivatives) would overflow; choose units that make it smaller
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise MaterialError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise MaterialError(f"{name} must be finite, got {value!r}")
    return _bounded(v, name)


def _positive(v: float, name: str) -> None:
    """Refuse ``v`` unless ``>= 1 / MAX_MODULUS`` (``<= 0``: "must be > 0")."""
    if v <= 0.0:
        raise MaterialError(f"{name} must be > 0, got {v:g}")
    if v < 1.0 / MAX_MODULUS:
        raise MaterialError(f"{name} = {v:g} is smaller than {1 / MAX_MODULUS:g}: products of "
                            "the moduli would underflow to 0; choose units that make it larger")


def lame_from_young(E: float, nu: float) -> tuple[float, float]:
    """``(mu, lam)`` of Young's modulus ``E > 0`` and Poisson ratio ``-1 < nu < 1/2``.

    >>> [round(v, 12) for v in lame_from_young(2.6, 0.3)]
    [1.0, 1.5]
    """
    E, nu = _finite(E, "Young's modulus E"), _finite(nu, "Poisson ratio nu")
    _positive(E, "Young's modulus E")
    if not -1.0 < nu < 0.5:
        raise MaterialError(f"Poisson ratio nu must lie in (-1, 0.5), got {nu:g}")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    if abs(lam) > MAX_MODULUS:
        raise MaterialError(f"Poisson ratio nu = {nu!r} with E = {E:g} gives lam = {lam:g}, "
                            f"larger than {MAX_MODULUS:g}: take nu further from 0.5")
    return E / (2.0 * (1.0 + nu)), lam


@dataclass(frozen=True)
class Material:
    """Base record: Lame moduli at rest and density.

    Parameters
    ----------
    mu, lam : float
        Lame moduli of the linearisation at rest; need ``mu > 0`` and ``lam > -2 mu / 3`` (a
        positive bulk modulus, equivalently ``-1 < nu < 1/2``).
    density : float
        Mass per unit volume (> 0; per unit area in 2D plane strain).

    Raises
    ------
    MaterialError
        Non-finite or out-of-range constants.
    """

    mu: float
    lam: float
    density: float = 1.0

    name: ClassVar[str] = "material"

    def __post_init__(self):
        mu = _finite(self.mu, f"{self.name}: shear modulus mu")
        lam = _finite(self.lam, f"{self.name}: lambda")
        rho = _finite(self.density, f"{self.name}: density")
        _positive(mu, f"{self.name}: shear modulus mu")
        if lam <= -2.0 * mu / 3.0:
            raise MaterialError(f"{self.name}: lambda = {lam:g} <= -2 mu / 3 = {-2 * mu / 3:g} "
                                "(negative bulk modulus: Poisson ratio <= -1)")
        _positive(rho, f"{self.name}: density")
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "lam", lam)
        object.__setattr__(self, "density", rho)

    @classmethod
    def from_young(cls, E: float, nu: float, density: float = 1.0, **extra) -> "Material":
        """The material with Young's modulus ``E`` and Poisson ratio ``nu`` (3D relations;
        in 2D the plane-strain body of the same material)."""
        mu, lam = lame_from_young(E, nu)
        return cls(mu, lam, density, **extra)

    @property
    def young(self) -> float:
        """Young's modulus ``mu (3 lam + 2 mu) / (lam + mu)``."""
        return self.mu * (3 * self.lam + 2 * self.mu) / (self.lam + self.mu)

    @property
    def poisson(self) -> float:
        """Poisson ratio ``lam / (2 (lam + mu))``."""
        return self.lam / (2.0 * (self.lam + self.mu))

    def params(self) -> np.ndarray:
        """The constants handed to the compiled energy, ``[mu, lam]`` by default."""
        return np.array([self.mu, self.lam])

    #: number of the material's point function in the compiled element pass
    #: (:func:`femkit.elements.compiled.point`)
    code: ClassVar[int] = -1

    def kernels(self):
        """The module of compiled kernels evaluating this material (``point``,
        ``element_pass``, ``stretch_energy``), generated from energy expressions
        (:mod:`femkit.solids.energy.codegen`): one module for all built-ins (given to every
        registered class by :func:`.registry.register_material`), one per material designed by
        its energy (:class:`.designed.EnergyMaterial`)."""
        raise MaterialError(f"{self.name}: neither a registered material nor designed by its "
                            "energy, so it has no compiled kernels")

    def kernels_cached(self) -> bool:
        """Whether :meth:`kernels` loads compiled code from the cache (no SymPy, no compiling)."""
        return True


@dataclass(frozen=True)
class StretchMaterial(Material):
    """A material given by its energy of the principal stretches (number ``code`` of the
    ``stretch_energy`` of its generated kernels, :meth:`Material.kernels`)."""


    def stretch_derivatives(self, s) -> tuple[float, np.ndarray, np.ndarray]:
        """``(W, dW/ds, d^2W/ds^2)`` at one set of stretches ``s`` (``d`` values)."""
        s = np.ascontiguousarray(s, dtype=float)
        g, H = np.zeros(len(s)), np.zeros((len(s), len(s)))
        W = self.kernels().stretch_energy(self.code, s, self.params(), g, H)
        return float(W), g, H
