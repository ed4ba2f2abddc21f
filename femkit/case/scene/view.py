"""The mass-spring kind's picture (:attr:`femkit.kinds.Kind.view` of ``problem: mass_spring``):
the cloth's triangles (a rope's springs as tubes, a mesh's springs as lines) coloured by the
speed of the nodes or the springs by their stretch, the pinned nodes in red, the obstacles the
scene declares (penalty ground plane and spheres, barrier contact's obstacles where their
prescribed motion puts them at each frame's time) in grey; one frame per recorded frame
(``scene.pvd``).
pyvista: ``femkit[view]``.

The obstacles come from the result in memory, or, for a run directory, from its case file as it
is now (``result.json``'s ``case_file``: a run made with ``--set`` on an obstacle is drawn with
the file's obstacle; a case file gone is drawn without them).
"""

from __future__ import annotations

import numpy as np

from ...errors import FemkitError
from ...view.core import Frame, Layer, Picture
from ...view.core.generic import flat, read_series
from ...view.core.render import pyvista
from ...view.core.source import Run, check_field

__all__ = ["scene_view", "obstacle_layers", "barrier_obstacle_layers"]

TITLES = {"speed": "speed (length units / s)", "stretch": "spring stretch (length / rest - 1)"}
_CONTACTS = ("ground", "sphere", "barrier contact")


def _forces(run: Run) -> list:
    """The scene's force objects (those that draw: ground, spheres)."""
    if run.result is not None:
        return list(run.result.system.forces)
    declared = run.facts.get("system", {}).get("forces", [])
    if not any(n in declared for n in _CONTACTS) or not run.facts.get("case_file"):
        return []
    from ..load import load_case
    from .run import build_system

    try:
        return list(build_system(load_case(run.facts["case_file"]))[0].forces)
    except (FemkitError, OSError):
        return []


def obstacle_layers(forces, lo: np.ndarray, hi: np.ndarray, dim: int) -> list[Layer]:
    """Grey layers of the ground planes and spheres among ``forces``, the ground spanning the
    box ``lo``..``hi`` (3D points) grown by half its size."""
    from ...dynamics.forces.contact import GroundContact, SphereContact

    pv = pyvista()
    centre, span = (lo + hi) / 2, max(float(np.max(hi - lo)), 1e-9)
    layers = []
    for f in forces:
        if isinstance(f, GroundContact):
            n = np.zeros(3)
            n[:dim] = f.unit_normal
            origin = centre - n * (centre @ n) + n * f.height
            if dim == 2:
                side = np.array([-n[1], n[0], 0.0]) * span
                mesh = pv.Line(origin - side, origin + side)
                layers.append(Layer(mesh, color="dimgrey", line_width=4))
            else:
                mesh = pv.Plane(center=origin, direction=n, i_size=2 * span, j_size=2 * span)
                layers.append(Layer(mesh, color="silver", opacity=0.6))
        elif isinstance(f, SphereContact):
            c = np.zeros(3)
            c[:dim] = np.asarray(f.centre, dtype=float)[:dim]
            mesh = (pv.Disc(center=c, inner=0.0, outer=f.radius, c_res=64) if dim == 2 else
                    pv.Sphere(radius=f.radius, center=c, theta_resolution=48, phi_resolution=48))
            layers.append(Layer(mesh, color="lightsteelblue", opacity=0.9))
    return layers


def barrier_obstacle_layers(forces, t: float, lo: np.ndarray, hi: np.ndarray,
                            dim: int) -> list[Layer]:
    """Grey layers of barrier contact's obstacles among ``forces`` at time ``t``
    (:meth:`femkit.contact.Obstacle.at`); a plane wider than the box ``lo``..``hi`` (3D points)
    drawn shrunk about its centre to 1.5 times the box's size (the default plane is 10 times
    the bodies' size: the camera would frame the plane, not the bodies). None in a picture of
    flat frames (``dim`` 2) of a 3-D scene, drawn from above like a plane scene."""
    from ...dynamics.forces.barrier import BarrierContact

    pv = pyvista()
    span = max(float(np.max(hi - lo)), 1e-9)
    layers = []
    for f in forces:
        for ob in getattr(f, "obstacles", ()) if isinstance(f, BarrierContact) else ():
            if ob.dim != dim:   # a 3-D scene whose frames are all flat, drawn from above
                continue
            V = np.zeros((len(ob.vertices), 3))
            V[:, :ob.dim] = ob.at(t)
            if ob.name == "plane":
                c = V.mean(axis=0)
                V = c + (V - c) * min(1.0, 1.5 * span / max(np.abs(V - c).max(), 1e-300))
            k = ob.faces.shape[1]
            cells = np.hstack([np.full((len(ob.faces), 1), k), ob.faces]).ravel()
            mesh = pv.PolyData(V, faces=cells) if k == 3 else pv.PolyData(V, lines=cells)
            layers.append(Layer(mesh, color="silver" if ob.name == "plane" else "lightsteelblue",
                                opacity=0.6 if ob.name == "plane" else 0.9, line_width=4))
    return layers


def _body_layers(mesh, name: str) -> list[Layer]:
    """The body of one frame: triangles or springs coloured by ``name``, and the pins."""
    pv = pyvista()
    mesh.point_data["speed"] = np.linalg.norm(np.asarray(mesh.point_data["velocity"]), axis=1)
    springs = mesh.extract_cells_by_type(pv.CellType.LINE)
    faces = mesh.extract_cells_by_type(pv.CellType.TRIANGLE)
    rope = faces.n_cells == 0
    if name == "stretch":
        body = [Layer(springs, "stretch", TITLES[name], cmap="coolwarm", tubes=rope, line_width=3)]
    elif rope:
        body = [Layer(springs, "speed", TITLES[name], tubes=True, line_width=5)]
    else:
        body = [Layer(faces, "speed", TITLES[name], edges=None)]
    pins = np.asarray(mesh.point_data["pinned"]) > 0 if "pinned" in mesh.point_data else []
    if np.any(pins):
        body.append(Layer(pv.PolyData(np.asarray(mesh.points)[pins]), color="red", style="points",
                          point_size=12, tubes=True))
    return body


def scene_view(run: Run, field: str | None = None, frames: int = 60) -> Picture:
    """The picture of a mass-spring run (from its run directory: ``scene.pvd`` and its frames).

    Parameters
    ----------
    run : Run
        The result (with its output directory) or the run directory.
    field : str, optional
        ``speed`` (default: the nodes' speed) or ``stretch`` (each spring's).
    frames : int
        At most this many frames (evenly spaced, the last included).
    """
    series = read_series(run.file("scene.pvd"), frames)
    fields = [f for f in TITLES if f != "stretch" or "stretch" in series[0][1].cell_data]
    name = check_field(field, fields, "speed")
    dim = 2 if all(flat(m) for _, m in series) else 3
    points = np.concatenate([np.asarray(m.points) for _, m in series])
    forces, lo, hi = _forces(run), points.min(axis=0), points.max(axis=0)
    obstacles = obstacle_layers(forces, lo, hi, dim)
    out = [Frame(_body_layers(mesh, name) + obstacles
                 + barrier_obstacle_layers(forces, t, lo, hi, dim), t) for t, mesh in series]
    clim = None
    if name == "stretch":
        m = max(float(np.abs(np.asarray(f.layers[0].mesh["stretch"])).max(initial=0.0))
                for f in out)
        clim = (-max(m, 1e-9), max(m, 1e-9))
    return Picture(out, title=f"{run.name}: {TITLES[name].split(' (')[0]}", dim=dim,
                   field=name, fields=tuple(fields), clim=clim)
