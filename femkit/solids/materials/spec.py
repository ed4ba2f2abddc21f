"""A material from a plain mapping (what a case file's ``material:`` holds): :func:`material_from_spec`.

One function turns ``{model: name, E: .., nu: .. | mu: .., lam: .., density: ..}`` or
``{energy: {f: .., g: .., h: ..} | {W: ..} | "W", constants: {..}, density: ..}`` (a material
designed by its energy, :class:`~femkit.solids.materials.designed.EnergyMaterial`) into a
:class:`~femkit.solids.materials.base.Material`, so the case layer and any other reader of
mappings build materials the same way. A new way of describing a material (for instance an
energy written by the user) is one more branch here, keyed by its own entry in the mapping.

>>> material_from_spec({"model": "stvk", "E": 2.6, "nu": 0.3}).mu
1.0
>>> material_from_spec({"model": "rubber", "E": 1.0, "nu": 0.3})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
femkit.errors.UnknownNameError: unknown material 'rubber'; valid materials: corotational, linear, ...
"""

from __future__ import annotations

from typing import Any, Mapping

from ...errors import MaterialError
from .base import Material
from .builtin_materials import MATERIALS, material

__all__ = ["material_from_spec", "SPEC_KEYS"]

#: The keys of a material mapping (the case schema's ``material`` object names the same).
SPEC_KEYS = ("model", "E", "nu", "mu", "lam", "density")


def material_from_spec(spec: Mapping[str, Any]) -> Material:
    """The material a mapping describes.

    Parameters
    ----------
    spec : mapping
        ``model`` (a name of :data:`MATERIALS`), either ``E`` and ``nu`` (Young's modulus,
        Poisson ratio) or ``mu`` and ``lam`` (Lame moduli), and ``density`` (default 1); or
        ``energy`` (the separable ``f, g, h`` or a full ``W``, docs/materials.md), its named
        ``constants`` and ``density``.

    Raises
    ------
    UnknownNameError
        ``model`` is not a registered material (the valid names are listed).
    MaterialError
        Missing, mixed, unknown or out-of-range constants (``E <= 0``, ``nu`` outside
        ``(-1, 1/2)``, ``density <= 0``).
    """
    if not isinstance(spec, Mapping):
        raise MaterialError(f"a material is a mapping {{model: ..., E: ..., nu: ...}}, got {spec!r}")
    if "energy" in spec:
        from .designed import ENERGY_KEYS, EnergyMaterial

        unknown = sorted(set(spec) - set(ENERGY_KEYS))
        if unknown:
            raise MaterialError(f"unknown material keys {', '.join(unknown)}; valid keys with an "
                                f"energy: {', '.join(ENERGY_KEYS)}")
        constants = spec.get("constants") or {}
        if not isinstance(constants, Mapping):
            raise MaterialError(f"material constants must be a mapping name: value, got {constants!r}")
        return EnergyMaterial.from_energy(spec["energy"], constants, spec.get("density", 1.0))
    unknown = sorted(set(spec) - set(SPEC_KEYS))
    if unknown:
        raise MaterialError(f"unknown material keys {', '.join(unknown)}; valid keys: "
                            f"{', '.join(SPEC_KEYS)} (or energy, constants, density)")
    if "model" not in spec:
        raise MaterialError(f"a material needs 'model', one of {', '.join(MATERIALS.names())}")
    MATERIALS.get(spec["model"])  # unknown names: UnknownNameError listing the valid ones
    return material(spec["model"], mu=spec.get("mu"), lam=spec.get("lam"), E=spec.get("E"),
                    nu=spec.get("nu"), density=spec.get("density", 1.0))
