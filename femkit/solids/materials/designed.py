"""A material designed by its energy of the principal stretches (Xu, Sin, Zhu & Barbic 2015).

:class:`EnergyMaterial` is a :class:`~.base.StretchMaterial` whose energy is a user's expression
(:class:`femkit.solids.energy.Energy`): checked at construction (finite and stress-free at rest,
stable, symmetric; :meth:`~femkit.solids.energy.Energy.check}`), its Lame-equivalent moduli at
rest become the record's ``mu``, ``lam``, and its kernels are generated and compiled
(:mod:`femkit.solids.energy.codegen`) on first evaluation. The built-in stretch materials are
written the same way (``energy_expression``, compiled together: :mod:`.builtin_kernels`);
:func:`designed` gives one's expression as a user's energy, with a module of its own.

>>> m = EnergyMaterial.from_energy({"f": "mu*(s-1)**2", "h": "lam/2*(J-1)**2"},
...                                {"mu": 1.0, "lam": 2.0})
>>> round(m.mu, 12), round(m.lam, 12)
(1.0, 2.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Mapping

import numpy as np

from ...errors import MaterialError
from ..energy.parse import sympy_time_limit
from .base import Material, StretchMaterial

__all__ = ["EnergyMaterial", "designed", "ENERGY_KEYS"]

#: The keys of a material mapping designed by its energy (:func:`.spec.material_from_spec`).
ENERGY_KEYS = ("energy", "constants", "density")

_SYMBOLIC: dict = {}   # (energy, constant names) -> SymPy W
_KERNELS: dict = {}    # (energy, constant names) -> generated module (one per process)


def _as_energy(energy):
    from ..energy import Energy

    if isinstance(energy, Energy):
        return energy
    if isinstance(energy, str):
        return Energy(W=energy)
    if isinstance(energy, Mapping):
        unknown = sorted(set(energy) - {"W", "f", "g", "h"})
        if unknown:
            raise MaterialError(f"energy: unknown key(s) {', '.join(map(repr, unknown))}; valid "
                                "keys: W (a full W(s1, s2, s3)) or f, g, h (separable)")
        return Energy(**{k: (None if v is None else str(v)) for k, v in energy.items()})
    raise MaterialError(f"energy must be a string or a mapping of W or f, g, h, got {energy!r}")


def _symbolic(energy, names: tuple):
    key = (energy, names)
    if key not in _SYMBOLIC:
        _SYMBOLIC[key] = energy.symbolic(names)
    return _SYMBOLIC[key]


@dataclass(frozen=True)
class EnergyMaterial(StretchMaterial):
    """A material given by its energy expression (module docstring). Build it with
    :meth:`from_energy`, which runs the checks and sets ``mu``, ``lam`` to the moduli at rest.

    Parameters
    ----------
    mu, lam, density
        As :class:`~.base.Material` (``mu``, ``lam``: the linearisation at rest).
    energy : femkit.solids.energy.Energy
    constants : tuple of (name, value)
        The named constants, in the order of :meth:`params`.
    label : str
        Name used in messages.
    """

    energy: object = None
    constants: tuple = ()
    label: str = "energy"

    name: ClassVar[str] = "energy"
    code: ClassVar[int] = 1   # any stretch energy: the generated module has one

    @classmethod
    def from_energy(cls, energy, constants: Mapping[str, float] | None = None, density: float = 1.0,
                    label: str = "energy") -> "EnergyMaterial":
        """The checked material of ``energy`` (an :class:`~femkit.solids.energy.Energy`, a
        string ``W`` or a mapping of ``W`` or ``f, g, h``) with the ``constants``' values.

        Raises
        ------
        MaterialError
            Unsafe or malformed expression, a constant without a value or a non-numeric one,
            an energy not finite, not stress-free or unstable at rest, a full ``W`` not
            symmetric in the stretches (one line each).
        """
        from .base import _finite

        energy = _as_energy(energy)
        consts = tuple((str(k), _finite(v, f"constant {k}")) for k, v in (constants or {}).items())
        names = tuple(k for k, _ in consts)
        what = f"{label} ({energy.describe()})"
        with sympy_time_limit(what if len(what) <= 100 else what[:97] + "..."):
            W = _symbolic(energy, names)
            moduli = energy.check(W, dict(consts), name=what)
        return cls(moduli.mu, moduli.lam, density, energy, consts, label)

    def params(self) -> np.ndarray:
        return np.array([v for _, v in self.constants], dtype=float)

    def _recipe(self) -> str:
        return f"{self.energy!r} ({', '.join(k for k, _ in self.constants)})"

    def kernels_cached(self) -> bool:
        from ..energy.codegen import module_cached

        return (self.energy, tuple(k for k, _ in self.constants)) in _KERNELS or \
            module_cached(self._recipe())

    def kernels(self):
        names = tuple(k for k, _ in self.constants)
        key = (self.energy, names)
        mod = _KERNELS.get(key)
        if mod is None:
            from ..energy.codegen import energy_module

            def build():
                import sympy

                return [(_symbolic(self.energy, names), sympy.symbols("s1:4"),
                         [sympy.Symbol(k) for k in names])]

            mod = energy_module(self._recipe(), build)
            _KERNELS[key] = mod
        return mod


def designed(material: Material) -> EnergyMaterial:
    """A built-in stretch material's ``energy_expression`` as a user's energy, with its ``mu``,
    ``lam`` and density (its own generated module, not the built-ins' shared one)."""
    expr = getattr(type(material), "energy_expression", None)
    if expr is None:
        raise MaterialError(f"material {material.name!r} is not written as an energy of the "
                            "principal stretches")
    return EnergyMaterial.from_energy(expr, {"mu": material.mu, "lam": material.lam},
                                      material.density, label=material.name)

