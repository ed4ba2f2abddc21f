"""Barrier contact in case files: the ``contact:`` mapping of scenes and solids, its checks, the
force it builds and what a run records of it.

Shared by the ``mass_spring`` and ``solid`` kinds (docs/scenes.md, docs/solids.md)::

    contact:
      dhat: 1.0e-3          # activation distance (default 1e-3 of the bodies' box diagonal)
      stiffness: 1.0e4      # a fixed barrier stiffness (default adaptive, IPC)
      friction: 0.3         # Coulomb mu (default 0)
      eps_v: 1.0e-3         # friction's slip-speed mollifier
      lagging: 1            # friction lagging iterations per step
      ccd: tight_inclusion  # or additive (cheaper, not certified against rounding)
      self: true            # a body may touch itself (default true)
      obstacles:
        - {type: plane, point: [0, 0, 0], normal: [0, 0, 1]}
        - {type: sphere, centre: [0, 0, 0.3], radius: 0.25}
        - {type: file, file: bowl.stl}
        - {type: plane, point: [0, 0, 0.5], velocity: [0, 0, -0.1]}     # moving
        - {type: file, file: paddle.stl, angular_velocity: [0, 0, 3.14],   # turning about
           pivot: [0, 0, 0], path: [[0, 0, 0, 0], [1, 0.2, 0, 0]]}        # a travelling pivot

Only integrators declaring ``keeps_contact`` run it (:func:`check_contact_integrator`, at load
time); the initial state is checked for intersections before anything is written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import CaseFileError, InputError, with_prefix
from .fragments import NONNEG, POS, VEC, closed

__all__ = ["CONTACT_SCHEMA", "MOTION", "check_contact_integrator", "build_contact",
           "ContactRecorder", "obstacle_facets"]

#: An obstacle's prescribed rigid motion (:class:`femkit.contact.Motion`): a constant
#: ``velocity`` or a keyframed ``path`` of ``[t, ux, uy(, uz)]`` rows (displacements, linear
#: between keys), and a constant ``angular_velocity`` (a rate in 2D, a vector in 3D) about a
#: ``pivot`` (default: the centre of the obstacle's bounding box at time 0).
MOTION = {"velocity": VEC,
          "path": {"type": "array", "minItems": 1,
                   "items": {"type": "array", "minItems": 3, "maxItems": 4,
                             "items": {"type": "number"}}},
          "angular_velocity": {"anyOf": [{"type": "number"},
                                         {"type": "array", "minItems": 3, "maxItems": 3,
                                          "items": {"type": "number"}}],
                               "x-message": "expected a number (2D) or 3 numbers (3D)"},
          "pivot": VEC}

_OBSTACLES = {
    "plane": closed({"type": {"const": "plane"}, "point": VEC, "normal": VEC, "size": POS,
                     **MOTION}, ["type"]),
    "sphere": closed({"type": {"const": "sphere"}, "centre": VEC, "radius": POS,
                      "level": {"type": "integer", "minimum": 0, "maximum": 6}, **MOTION},
                     ["type", "centre", "radius"]),
    "file": closed({"type": {"const": "file"}, "file": {"type": "string", "minLength": 1},
                    **MOTION}, ["type", "file"]),
}

#: The ``contact:`` mapping (closed; obstacles by ``type``).
CONTACT_SCHEMA = closed({
    "dhat": POS, "stiffness": POS, "friction": NONNEG, "eps_v": POS,
    "lagging": {"type": "integer", "minimum": 1}, "self": {"type": "boolean"},
    "ccd": {"enum": ["tight_inclusion", "additive"]},
    "obstacles": {"type": "array", "items": {
        "type": "object", "required": ["type"],
        "properties": {"type": {"enum": sorted(_OBSTACLES)}},
        "allOf": [{"if": {"properties": {"type": {"const": k}}, "required": ["type"]},
                   "then": v} for k, v in _OBSTACLES.items()]}},
}, [])


def check_contact_integrator(method: str) -> None:
    """Refuse (CaseFileError) an integrator that does not keep barrier contact, naming those
    that do (from the integrators' ``keeps_contact`` trait)."""
    from ..dynamics.integrators import INTEGRATORS
    from ..dynamics.integrators.base import contact_refusal

    if not getattr(INTEGRATORS.get(method), "keeps_contact", False):
        raise CaseFileError(contact_refusal(method))


def resolve_obstacle_files(contact: dict, base: Path) -> None:
    """Make every obstacle ``file`` absolute (relative to the case file) and check it exists."""
    for i, ob in enumerate(contact.get("obstacles") or []):
        if ob["type"] == "file":
            path = (base / ob["file"]).resolve()
            if not path.is_file():
                raise CaseFileError(f"contact.obstacles[{i}].file: {ob['file']} not found")
            ob["file"] = str(path)


def _obstacles(contact, x0: np.ndarray) -> list:
    from ..contact import file_obstacle, plane_obstacle, sphere_obstacle

    dim = x0.shape[1]
    lo, hi = x0.min(axis=0), x0.max(axis=0)
    length = float(np.linalg.norm(hi - lo)) or 1.0
    out = []
    for i, ob in enumerate(contact.get("obstacles") or []):
        try:
            if ob["type"] == "plane":
                normal = ob.get("normal", np.eye(dim)[-1])
                centre = 0.5 * (lo + hi)
                point = np.asarray(ob.get("point", np.zeros(dim)), float)
                n = np.asarray(normal, float) / (np.linalg.norm(normal) or 1.0)
                foot = centre - np.dot(centre - point, n) * n   # the plane's point nearest the bodies
                out.append(plane_obstacle(foot, normal, ob.get("size", 10.0 * length), dim))
            elif ob["type"] == "sphere":
                out.append(sphere_obstacle(ob["centre"], ob["radius"], dim, ob.get("level", 3)))
            else:
                out.append(file_obstacle(ob["file"], dim))
            if any(k in ob for k in MOTION):
                out[-1] = _moving(out[-1], ob, dim)
        except (InputError, ValueError) as exc:
            raise with_prefix(InputError(str(exc).removeprefix("contact.obstacles: ")),
                              f"contact.obstacles[{i}]") from None
    return out


def _finite(value, shape: tuple, key: str, what: str) -> np.ndarray:
    a = np.asarray(value, float)
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise InputError(f"{key} must be {what}, got {value!r}")
    return a


def _path(path, dim: int) -> np.ndarray:
    """A keyframed path's rows ``[t, u_1 .. u_dim]``, checked (times strictly increasing)."""
    rows = [_finite(r, (dim + 1,), f"path[{i}]", f"[t, {dim} displacements] ({dim + 1} finite "
                    "numbers)") for i, r in enumerate(path)]
    a = np.array(rows)
    if np.any(np.diff(a[:, 0]) <= 0.0):
        raise InputError(f"path: the keyframe times must increase strictly, got "
                         f"{a[:, 0].tolist()!r}")
    return a


def _moving(obstacle, ob: dict, dim: int):
    """``obstacle`` in the rigid motion its mapping ``ob`` prescribes (:data:`MOTION`'s keys)."""
    from dataclasses import replace

    from ..contact import Motion

    if "velocity" in ob and "path" in ob:
        raise InputError("give a velocity or a path, not both (a path's rows are "
                         "[t, displacement])")
    v = (_finite(ob["velocity"], (dim,), "velocity", f"{dim} finite numbers")
         if "velocity" in ob else None)
    path = _path(ob["path"], dim) if "path" in ob else None
    omega, pivot = ob.get("angular_velocity"), None
    if omega is not None:
        omega = _finite(omega, () if dim == 2 else (3,), "angular_velocity",
                        "a number (a rate in 2D)" if dim == 2 else "3 finite numbers (3D)")
        verts = obstacle.vertices
        pivot = _finite(ob.get("pivot", 0.5 * (verts.min(axis=0) + verts.max(axis=0))), (dim,),
                        "pivot", f"{dim} finite numbers")
    elif "pivot" in ob:
        raise InputError("pivot: only with an angular_velocity (the point it turns about)")
    return replace(obstacle, motion=Motion(velocity=v, path=path, angular_velocity=omega,
                                           pivot=pivot))


def build_contact(contact, x0, cells):
    """The (unbound) :class:`~femkit.dynamics.forces.BarrierContact` of a ``contact:`` mapping
    for bodies at ``x0`` with ``cells`` (tetrahedra, triangles or segments); the caller checks
    the initial state (:meth:`~femkit.contact.barrier.BarrierModel.check_intersection_free`)."""
    from ..contact import body_surface
    from ..dynamics.forces import BarrierContact

    x0 = np.asarray(x0, float)
    surface = body_surface(cells, x0.shape[1])
    force = BarrierContact(surface, _obstacles(contact, x0), dhat=contact.get("dhat"),
                           stiffness=contact.get("stiffness"),
                           self_contact=bool(contact.get("self", True)),
                           mu=float(contact.get("friction", 0.0)),
                           eps_v=float(contact.get("eps_v", 1e-3)),
                           lagging=int(contact.get("lagging", 1)),
                           ccd=contact.get("ccd", "tight_inclusion"))
    return force


def obstacle_facets(contact) -> float:
    """Facets of a ``contact:`` mapping's obstacles from its numbers (a sphere ``20 * 4^level``,
    a plane 2; a file's counted as 2,000): what the plan's contact stage is priced on
    (:func:`femkit.cost.contact_stage`) with the bodies' surface."""
    sizes = {"sphere": lambda o: 20 * 4 ** o.get("level", 3), "plane": lambda o: 2,
             "file": lambda o: 2000}
    return float(sum(sizes[o["type"]](o) for o in contact.get("obstacles") or []))


class ContactRecorder:
    """Per recorded frame: the contact force (VTU point data), the minimum distance, the number
    of active pairs and the independent intersection count; :meth:`facts` for result.json."""

    def __init__(self, force):
        self.force = force
        self.frames: list[dict] = []

    def record(self, t: float, x: np.ndarray) -> dict:
        """The frame's facts (kept) and its point data ``{"contact_force": (n, 3)}``."""
        m = self.force.model
        d = m.min_distance(x)
        self.frames.append({"t": float(t), "min_distance": d, "active_contacts": m.active(x),
                            "intersections": m.intersections(x)})
        f = -m.gradient(x)
        return {"contact_force": np.pad(f, ((0, 0), (0, 3 - f.shape[1])))}

    def facts(self) -> dict:
        """The ``contact`` entry of result.json."""
        m = self.force.model
        dists = [f["min_distance"] for f in self.frames if f["min_distance"] is not None]
        return {"dhat": m.dhat, "stiffness": m.kappa_value,
                "stiffness_adaptive": m.fixed_stiffness is None, "friction": m.mu,
                "eps_v": m.eps_v, "self": m.self_contact, "ccd": m.ccd_method,
                "obstacles": [o.name for o in self.force.obstacles],
                "min_distance": min(dists) if dists else None,
                "intersections": int(sum(f["intersections"] for f in self.frames)),
                "frames": self.frames, "stats": dict(m.stats),
                "seconds": {k: round(v, 6) for k, v in m.seconds.items()}}

    def summary_line(self) -> str:
        f = self.facts()
        d = "none within 10 dhat" if f["min_distance"] is None else f"{f['min_distance']:.3e}"
        peak = max((fr["active_contacts"] for fr in self.frames), default=0)
        return (f"contact   barrier (dhat {f['dhat']:.3g}, stiffness {f['stiffness']:.3g}): "
                f"minimum distance {d}, up to {peak} active pairs, "
                f"{f['intersections']} intersections in {len(self.frames)} frames")
