"""Forces a scene file can declare (``forces:``): the registry :data:`FORCES`.

Each entry is a :class:`ForceType`: the JSON schema of its parameters and the builder of the
force object. The scene schema's ``forces`` enum and per-type branches are derived from this
registry, so a force registered here (or by a plugin, :mod:`femkit.plugins`) is accepted
by scene files without touching the schema::

    from femkit.case.scene.forces import FORCES, ForceType

    FORCES.register("wind", ForceType(
        schema={"type": "object", "additionalProperties": False, "required": ["v"],
                "properties": {"v": {"type": "array", "items": {"type": "number"}}}},
        build=lambda p: Wind(p["v"])))

A force object implements the protocol of :mod:`femkit.dynamics.forces` (``force``,
``energy``, and for implicit integrators ``stiffness``/``damping``). Builders import the
dynamics layer when called, so listing forces imports nothing heavy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from ...registry import Registry
from ..fragments import NONNEG, POS, VEC, closed

__all__ = ["ForceType", "FORCES"]


@dataclass(frozen=True)
class ForceType:
    """One kind of force in scene files.

    Parameters
    ----------
    schema : dict
        JSON schema of the force's mapping without its ``type`` key (closed object).
    build : callable
        ``build(params) -> force object`` (``params``: the validated mapping, ``type``
        included); None for a force the scene folds into the springs (see ``spring_damping``).
    repeatable : bool
        Whether a scene may declare it more than once (e.g. several spheres).
    spring_damping : str or None
        Name of the parameter that is a dashpot coefficient along every spring (``dashpot``:
        ``c``) instead of a force object.
    shorthand : dict or None
        In the mapping form ``forces: {name: value}``, the schema of a bare value and the
        parameter it stands for: ``{"param": "g", "schema": {...}}`` (``gravity: 9.81``).
    """

    schema: dict
    build: Callable[[dict], Any] | None
    repeatable: bool = False
    spring_damping: str | None = None
    shorthand: dict | None = None


#: force type -> :class:`ForceType`
FORCES: Registry = Registry("force")


def _gravity(f: dict):
    import numpy as np

    from ...dynamics.forces import Gravity

    g = f.get("g", 9.81)
    return Gravity(g, axis=int(f.get("axis", -1))) if np.ndim(g) == 0 else Gravity(list(g))


def _viscous(f: dict):
    from ...dynamics.forces import ViscousDamping

    return ViscousDamping(f["gamma"], per_mass=bool(f.get("per_mass", False)))


def _rayleigh(f: dict):
    from ...dynamics.forces import RayleighDamping

    return RayleighDamping(f.get("alpha", 0.0), f.get("beta", 0.0))


def _ground(f: dict):
    from ...dynamics.forces import GroundContact

    return GroundContact(f["stiffness"], f.get("height", 0.0), f.get("normal"))


def _sphere(f: dict):
    from ...dynamics.forces import SphereContact

    return SphereContact(f["centre"], f["radius"], f["stiffness"])


FORCES.register("gravity", ForceType(
    closed({"g": {"anyOf": [NONNEG, VEC], "x-message": "expected a magnitude >= 0 or a vector"},
            "axis": {"type": "integer"}}, []), _gravity,
    shorthand={"param": "g", "schema": {"anyOf": [NONNEG, VEC]}}))
FORCES.register("dashpot", ForceType(closed({"c": NONNEG}, ["c"]), None, spring_damping="c"))
FORCES.register("viscous", ForceType(
    closed({"gamma": NONNEG, "per_mass": {"type": "boolean"}}, ["gamma"]), _viscous))
FORCES.register("rayleigh", ForceType(closed({"alpha": NONNEG, "beta": NONNEG}, []), _rayleigh))
FORCES.register("ground", ForceType(
    closed({"height": {"type": "number"}, "stiffness": POS, "normal": VEC}, ["stiffness"]),
    _ground))
FORCES.register("sphere", ForceType(
    closed({"centre": VEC, "radius": POS, "stiffness": POS}, ["centre", "radius", "stiffness"]),
    _sphere, repeatable=True))
