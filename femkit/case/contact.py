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

Only integrators declaring ``keeps_contact`` run it (:func:`check_contact_integrator`, at load
time); the initial state is checked for intersections before anything is written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import CaseFileError, InputError, with_prefix
from .fragments import NONNEG, POS, VEC, closed

__all__ = ["CONTACT_SCHEMA", "check_contact_integrator", "build_contact", "ContactRecorder",
           "contact_stage", "obstacle_facets", "CONTACT_ITERATIONS", "CONTACT_SECONDS_PER_FACET"]

_OBSTACLES = {
    "plane": closed({"type": {"const": "plane"}, "point": VEC, "normal": VEC, "size": POS,
                     "velocity": VEC}, ["type"]),
    "sphere": closed({"type": {"const": "sphere"}, "centre": VEC, "radius": POS,
                      "level": {"type": "integer", "minimum": 0, "maximum": 6}, "velocity": VEC},
                     ["type", "centre", "radius"]),
    "file": closed({"type": {"const": "file"}, "file": {"type": "string", "minLength": 1},
                    "velocity": VEC}, ["type", "file"]),
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
            if "velocity" in ob:
                out[-1] = _moving(out[-1], ob["velocity"], dim)
        except (InputError, ValueError) as exc:
            raise with_prefix(InputError(str(exc).removeprefix("contact.obstacles: ")),
                              f"contact.obstacles[{i}]") from None
    return out


def _moving(obstacle, velocity, dim: int):
    """``obstacle`` moving at ``velocity`` (a vector of the scene's dimension)."""
    from dataclasses import replace

    v = np.asarray(velocity, float)
    if v.shape != (dim,) or not np.all(np.isfinite(v)):
        raise InputError(f"velocity must be {dim} finite numbers, got {list(velocity)!r}")
    return replace(obstacle, velocity=v)


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


#: Barrier contact's price: Newton iterations of a step in contact (IPC's line search bounded by
#: CCD; 9.2 a contact step of the cloth_on_sphere at 21 x 21, 12.8 at 41 x 41 over 30 steps,
#: benchmarks/bench_contact.py) and seconds per surface facet per iteration of the broad phase,
#: CCD and barrier Hessian together (2.5e-5 s measured there on the shared 2-core machine).
CONTACT_ITERATIONS = 12.0
CONTACT_SECONDS_PER_FACET = 2.5e-5


def contact_stage(steps: int, facets: float):
    """The contact overhead of ``steps`` steps on ``facets`` surface facets (obstacles included),
    priced from the numbers before the run (first steps are often contact-free, so a measured
    first batch would miss it)."""
    from ..cost.plan import Stage

    sec = steps * CONTACT_ITERATIONS * facets * CONTACT_SECONDS_PER_FACET
    return Stage("contact", sec, 0.0, detail=f"barrier contact: ~{facets:.3g} facets, "
                 f"{CONTACT_ITERATIONS:g} CCD-bounded Newton iterations per step")


def obstacle_facets(contact) -> float:
    """Facets of a ``contact:`` mapping's obstacles from its numbers (a sphere ``20 * 4^level``,
    a plane 2; a file's counted as 2,000)."""
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
