"""The scenes of the ``springs_vs_elements`` study: the registry :data:`SVSE_SCENES`.

Each scene is a gmsh geometry, its supports and external forces, and the scalar it tracks over
time (the quantity whose error the study measures). Both are 2D (plane strain for the elements,
thickness 1), so the same triangle mesh carries the springs and the elements:

* ``hanging_beam``: a ``length x height`` beam (gmsh ``rectangle``) clamped at ``x = 0`` (the
  nodes of the ``left`` side pinned), released straight under gravity; tracked: the tip
  deflection, the mean downward displacement of the ``right`` side's nodes (a mean over a
  side, so meshes of different ``h`` measure the same thing); compared across meshes: its
  value at ``t_end``, settled by the mass-proportional ``damping``.
* ``falling_disk``: a disk (gmsh ``disk``) of ``radius`` released at ``gap`` above the ground
  ``y = 0`` with penalty contact; tracked: the squash ``1 - (vertical extent) / (2 radius)``;
  compared across meshes: its peak at the impact.
  The penalty stiffness is ``contact_stiffness * h`` per node, so the ground's stiffness per
  unit length does not grow as the mesh is refined.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...registry import Registry

__all__ = ["SceneType", "SVSE_SCENES", "scene_mesh"]


@dataclass(frozen=True)
class SceneType:
    """One scene: ``schema`` (its keys with defaults), ``geometry(params) -> (name, geometry
    params)``, ``pinned(mesh, params) -> nodes``, ``forces(params, h) -> [Force]``,
    ``quantity(mesh, params) -> f(x (n, 2)) -> float`` and its label, ``summary(q (steps,))
    -> float``: the one number of the run compared across mesh sizes (``value_label``)."""

    schema: dict
    geometry: Callable
    pinned: Callable
    forces: Callable
    quantity: Callable
    label: str
    description: str
    summary: Callable
    value_label: str


#: scene name -> :class:`SceneType`
SVSE_SCENES: Registry = Registry("springs_vs_elements scene")

_POS = {"type": "number", "exclusiveMinimum": 0}
_HLIST = {"type": "array", "items": _POS, "minItems": 2}


def _common(**defaults) -> dict:
    """Keys every scene has: mesh sizes, reference mesh size, step, end time, gravity."""
    return {"h": {**_HLIST, "default": defaults["h"]},
            "reference_h": {**_POS, "default": defaults["reference_h"]},
            "dt": {**_POS, "default": defaults["dt"]},
            "t_end": {**_POS, "default": defaults["t_end"]},
            "gravity": {"type": "number", "minimum": 0, "default": 9.81},
            "damping": {"type": "number", "minimum": 0, "default": defaults.get("damping", 0.0),
                        "description": "mass-proportional damping rate (force -damping m v)"}}


def scene_mesh(scene: SceneType, params, h: float):
    """The scene's validated gmsh mesh at size ``h``."""
    from ...mesh import generate, validate

    name, geo = scene.geometry(params)
    return validate(generate(name, float(h), **geo))


def _gravity(params) -> list:
    """Gravity, and mass-proportional damping ``-damping m v`` (the same for every model)."""
    from ...dynamics.forces.gravity import Gravity
    from ...dynamics.forces.viscous import ViscousDamping

    out = [Gravity(float(params["gravity"]))] if params["gravity"] else []
    if params.get("damping"):
        out.append(ViscousDamping(float(params["damping"]), per_mass=True))
    return out


def _side_nodes(mesh, tag: str) -> np.ndarray:
    return np.unique(mesh.boundary_edges[mesh.boundary_tags == mesh.tag(tag)])


def _tip_deflection(mesh, params):
    tip = _side_nodes(mesh, "right")
    y0 = mesh.points[tip, 1].mean()
    return lambda x: float(y0 - x[tip, 1].mean())


SVSE_SCENES.register("hanging_beam", SceneType(
    schema={**_common(h=[0.05, 0.035, 0.025, 0.0175, 0.0125], reference_h=0.00625, dt=0.02,
                      t_end=1.2, damping=12.0),
            "length": {**_POS, "default": 0.4}, "height": {**_POS, "default": 0.1}},
    geometry=lambda p: ("rectangle", dict(x0=0.0, y0=0.0, x1=float(p["length"]),
                                          y1=float(p["height"]))),
    pinned=lambda mesh, p: _side_nodes(mesh, "left"),
    forces=lambda p, h: _gravity(p),
    quantity=_tip_deflection, label="tip deflection",
    description="beam clamped at x = 0, released straight under gravity",
    summary=lambda q: float(q[-1]), value_label="tip deflection at the end (settled)"))


def _squash(mesh, params):
    r = float(params["radius"])
    return lambda x: float(1.0 - (x[:, 1].max() - x[:, 1].min()) / (2.0 * r))


def _disk_forces(p, h) -> list:
    from ...dynamics.forces.contact import GroundContact

    return _gravity(p) + [GroundContact(float(p["contact_stiffness"]) * float(h), height=0.0)]


SVSE_SCENES.register("falling_disk", SceneType(
    schema={**_common(h=[0.08, 0.056, 0.04, 0.028], reference_h=0.014, dt=0.004, t_end=0.6),
            "radius": {**_POS, "default": 0.3}, "gap": {**_POS, "default": 0.1},
            "contact_stiffness": {**_POS, "default": 1.0e8,
                                  "description": "penalty per node = this * h"}},
    geometry=lambda p: ("disk", dict(centre=(0.0, float(p["radius"]) + float(p["gap"])),
                                     radius=float(p["radius"]))),
    pinned=lambda mesh, p: np.zeros(0, np.intp),
    forces=_disk_forces,
    quantity=_squash, label="squash 1 - height / diameter",
    description="disk released above the ground, penalty contact",
    summary=lambda q: float(np.max(q)), value_label="peak squash at the impact"))
