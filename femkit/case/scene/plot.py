"""Pictures of a mass-spring run: the final frame as a PNG, the whole run as an animated GIF.

Every picture has two panels: the scene and the energy of the run (kinetic, potential =
spring + gravity + contact, total, against time), so one look tells what happened and whether
the run was healthy. An unstable run is marked: a red dashed line at the time it stopped on the
energy panel and ``UNSTABLE at step N`` in the title.

* 3-D systems: a real 3-D view (:mod:`mpl_toolkits.mplot3d`) with equal aspect (box aspect from
  the data ranges), elevation 25 deg and an azimuth looking across the line of the pinned nodes
  (so a cloth hanging from two corners shows its drape). Cloth and mesh systems are drawn as
  shaded triangles; systems without triangles as springs coloured by strain.
* 2-D systems: equal aspect, springs coloured by strain over light triangles (when known), and the
  path of one or two tracked nodes as a faint line.
* Strain ``(l - L) / L`` uses a diverging colour map centred at 0 (``vmin = -vmax``) with a
  colour bar. Pinned nodes are red squares. A declared ground plane and spheres are drawn.

The GIF uses the same style with fixed axes, colour range and energy axes over the whole
animation (limits from all frames), at most ``max_frames`` frames, one shared 128-colour
palette (small files), and a frame time that maps simulated time to a playback of 2-8 s.

Matplotlib and Pillow are imported inside the functions only (``femkit solve`` without ``png``
or ``gif`` imports neither).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ...io.figures import new_figure
from ..pictures import gif_frame_times, gif_frames, rgb_image, save_gif

__all__ = ["spring_strain", "tracked_nodes", "SceneView", "scene_view", "plot_frame",
           "write_final_png", "write_gif", "gif_frames", "gif_frame_times"]

_SURFACE = np.array([0.62, 0.78, 0.93])          # light blue cloth/mesh
_PIN = "#c0392b"


def spring_strain(system, x: np.ndarray) -> np.ndarray:
    """Engineering strain ``(l - L) / L`` of every spring at positions ``x`` ``(n, d)``.

    >>> from femkit.dynamics.topology import rope
    >>> s = rope(3, 2.0, k=1.0)
    >>> spring_strain(s, s.x0 * 1.5).round(3).tolist()
    [0.5, 0.5]
    """
    x = np.asarray(x, dtype=float)
    i, j = system.springs[:, 0], system.springs[:, 1]
    return np.linalg.norm(x[j] - x[i], axis=1) / system.rest - 1.0


def tracked_nodes(system, x0: np.ndarray | None = None, count: int = 2) -> np.ndarray:
    """One or two free nodes whose paths tell the motion (at most ``count``).

    With pinned nodes: the free node farthest from the pins' centroid (a rope's loose end) and
    the one nearest half that distance. Without pins: the node nearest the centroid and the one
    farthest from it (shows translation and rotation/squash).
    """
    x = np.asarray(system.x0 if x0 is None else x0, dtype=float)
    free = np.flatnonzero(~system.pinned)
    if not len(free) or count < 1:
        return np.zeros(0, dtype=np.int64)
    if system.pinned.any():
        r = np.linalg.norm(x[free] - x[system.pinned].mean(axis=0), axis=1)
        first = free[np.argmax(r)]
        second = free[np.argmin(np.abs(r - 0.5 * r.max()))]
    else:
        r = np.linalg.norm(x[free] - x[free].mean(axis=0), axis=1)
        first, second = free[np.argmin(r)], free[np.argmax(r)]
    out = [int(first)] + ([int(second)] if second != first else [])
    return np.asarray(out[:count], dtype=np.int64)


def _contacts(system):
    """(ground list, sphere list) among the declared forces."""
    from ...dynamics.forces.contact import GroundContact, SphereContact

    grounds = [f for f in system.forces if isinstance(f, GroundContact)]
    spheres = [f for f in system.forces if isinstance(f, SphereContact)]
    return grounds, spheres


@dataclass
class SceneView:
    """What stays fixed across the frames of one picture or animation.

    ``lo``/``hi`` axis limits ``(d,)``; ``strain_max`` the colour range ``[-strain_max,
    strain_max]``; ``tracks`` tracked node ids; ``elev``/``azim`` the 3-D viewpoint;
    ``energy_limits`` the energy panel's y range.
    """

    lo: np.ndarray
    hi: np.ndarray
    strain_max: float
    tracks: np.ndarray
    elev: float
    azim: float
    energy_limits: tuple[float, float]


def _azimuth(system, x: np.ndarray) -> float:
    """Camera azimuth (deg) looking across the pins' line, 30 deg off, from the body's side."""
    pins = x[system.pinned]
    if system.dim != 3 or len(pins) < 2:
        return -60.0
    d = pins[np.argmax(np.linalg.norm(pins - pins[0], axis=1))] - pins[0]
    if np.hypot(d[0], d[1]) < 1e-12:
        return -60.0
    perp = np.array([-d[1], d[0]])
    side = x[~system.pinned, :2].mean(axis=0) - pins[:, :2].mean(axis=0) if (~system.pinned).any() else perp
    if perp @ side < 0:
        perp = -perp
    return float(np.degrees(np.arctan2(perp[1], perp[0])) + 30.0)


def _energy_series(traj) -> dict[str, np.ndarray]:
    e = traj.energies
    pot = sum(np.asarray(e[k], dtype=float) for k in ("spring", "gravity", "contact") if k in e)
    return {"kinetic": np.asarray(e["kinetic"], float), "potential": np.asarray(pot, float),
            "total": np.asarray(e["total"], float)}


def scene_view(system, traj, frames: Sequence[int] | None = None) -> SceneView:
    """The fixed view of ``frames`` (default: every recorded frame) of ``traj``.

    Limits cover every picked frame, the tracked paths, the declared ground height (when the
    ground normal is an axis) and spheres, padded by 5 %.
    """
    picks = np.arange(len(traj.times)) if frames is None else np.asarray(frames, dtype=int)
    xs = np.asarray(traj.x)[picks]
    lo, hi = xs.min(axis=(0, 1)), xs.max(axis=(0, 1))
    grounds, spheres = _contacts(system)
    for g in grounds:
        axis = np.flatnonzero(np.abs(g.unit_normal) > 1 - 1e-12)
        if len(axis):
            a = axis[0]
            h = g.height * np.sign(g.unit_normal[a])
            lo[a], hi[a] = min(lo[a], h), max(hi[a], h)
    for s in spheres:
        lo = np.minimum(lo, s._c - s.radius)
        hi = np.maximum(hi, s._c + s.radius)
    span = max(float(np.max(hi - lo)), 1e-9)
    grow = np.maximum(0.0, 0.4 * span - (hi - lo)) / 2      # no axis thinner than 40 %
    lo, hi = lo - grow - 0.05 * span, hi + grow + 0.05 * span
    strain = np.abs(np.stack([spring_strain(system, x) for x in xs])) if system.n_springs else np.zeros(1)
    smax = float(np.max(strain[np.isfinite(strain)], initial=0.0))
    es = _energy_series(traj)
    vals = np.concatenate(list(es.values()))
    vals = vals[np.isfinite(vals)]
    elo, ehi = (float(vals.min()), float(vals.max())) if len(vals) else (0.0, 1.0)
    pad = 0.06 * max(ehi - elo, 1e-12 * max(abs(elo), abs(ehi), 1.0), 1e-300)
    return SceneView(lo=lo, hi=hi, strain_max=max(smax, 1e-6),
                     tracks=tracked_nodes(system, traj.x[0]), elev=25.0,
                     azim=_azimuth(system, np.asarray(traj.x[-1])),
                     energy_limits=(elo - pad, ehi + pad))


def _stop(traj) -> tuple[int, float] | None:
    """(step, time) at which an unstable run stopped, ``None`` for a completed run."""
    if getattr(traj, "completed", True):
        return None
    step = int(traj.steps) + 1
    return step, step * float(traj.dt)


def _title(name: str, traj, k: int) -> tuple[str, str]:
    e = traj.energies["total"]
    scale = float(getattr(traj, "energy_scale", 1.0)) or 1.0
    drift = float((e[k] - e[0]) / scale)
    text = f"{name}   t = {traj.times[k]:.3f} s   energy drift {drift:+.2e}"
    stop = _stop(traj)
    if stop is not None:
        return text + f"\nUNSTABLE at step {stop[0]} (t = {stop[1]:.4g} s)", _PIN
    return text, "black"


def _strain_mappable(view: SceneView):
    from matplotlib.colors import Normalize

    return "RdBu_r", Normalize(vmin=-view.strain_max, vmax=view.strain_max)


def _shade(pts: np.ndarray) -> np.ndarray:
    """Face colours of triangles ``(m, 3, 3)``: light colour, brightness from the normal."""
    n = np.cross(pts[:, 1] - pts[:, 0], pts[:, 2] - pts[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    light = np.array([-0.4, -0.5, 0.77])
    light /= np.linalg.norm(light)
    b = 0.4 + 0.6 * np.abs(n @ light)               # two-sided
    rgb = np.clip(_SURFACE[None, :] * b[:, None] + 0.08, 0, 1)
    return np.column_stack([rgb, np.ones(len(rgb))])


def _plane_quad(g, lo, hi) -> np.ndarray | None:
    """Corners (4, 3) of the ground plane over the box, ``None`` when it misses the box."""
    n = g.unit_normal
    axis = np.flatnonzero(np.abs(n) > 1 - 1e-12)
    if len(axis):
        a = axis[0]
        h = g.height * np.sign(n[a])
        b, c = [i for i in range(3) if i != a]
        quad = np.zeros((4, 3))
        quad[:, a] = h
        quad[:, b] = [lo[b], hi[b], hi[b], lo[b]]
        quad[:, c] = [lo[c], lo[c], hi[c], hi[c]]
        return quad
    centre = 0.5 * (lo + hi)
    p = centre - (centre @ n - g.height) * n
    t1 = np.cross(n, np.eye(3)[np.argmin(np.abs(n))])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    r = 0.5 * float(np.max(hi - lo))
    return np.array([p + r * (s1 * t1 + s2 * t2) for s1, s2 in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _draw_3d(fig, rect, system, x, triangles, view: SceneView, name, traj, k):
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    ax = fig.add_axes(rect, projection="3d")
    lo, hi = view.lo, view.hi
    grounds, spheres = _contacts(system)
    for g in grounds:
        quad = _plane_quad(g, lo, hi)
        ax.add_collection3d(Poly3DCollection([quad], facecolors=[(0.55, 0.45, 0.35, 0.25)],
                                             edgecolors=[(0.4, 0.3, 0.2, 0.6)], linewidths=0.8))
    for s in spheres:
        u, w = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
        c, r = s._c, s.radius
        ax.plot_surface(c[0] + r * np.cos(u) * np.sin(w), c[1] + r * np.sin(u) * np.sin(w),
                        c[2] + r * np.cos(w), color="0.6", alpha=0.35, linewidth=0, shade=True)
    mappable = None
    if triangles is not None and len(triangles):
        pts = x[np.asarray(triangles)]
        # thin edges while they can be told apart; a dense mesh reads better by shading alone
        faces = _shade(pts)
        edges = (0.2, 0.3, 0.45, 0.55) if len(pts) <= 3000 else faces   # faces: no seams
        ax.add_collection3d(Poly3DCollection(pts, facecolors=faces, edgecolors=edges,
                                             linewidths=0.3))
    elif system.n_springs:
        cmap, norm = _strain_mappable(view)
        seg = np.stack([x[system.springs[:, 0]], x[system.springs[:, 1]]], axis=1)
        lc = Line3DCollection(seg, cmap=cmap, norm=norm, linewidths=2.2)
        lc.set_array(spring_strain(system, x))
        ax.add_collection3d(lc)
        free = ~system.pinned
        ax.scatter(*x[free].T, s=6, c="k", depthshade=False)
        mappable = lc
    pins = x[system.pinned]
    if len(pins):
        ax.scatter(*pins.T, s=30, marker="s", c=_PIN, depthshade=False, zorder=10, label="pinned")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    span = hi - lo
    ax.set_box_aspect(np.maximum(span, 0.05 * span.max()), zoom=1.15)
    ax.view_init(elev=view.elev, azim=view.azim)
    ax.set_xlabel("x", labelpad=-6)
    ax.set_ylabel("y", labelpad=-6)
    ax.set_zlabel("z", labelpad=-6)
    ax.tick_params(labelsize=8, pad=-2)
    for pane in (ax.xaxis, ax.yaxis, ax.zaxis):
        pane.set_pane_color((0.96, 0.96, 0.96, 1.0))
    return ax, mappable


def _draw_2d(fig, rect, system, x, triangles, view: SceneView, name, traj, k):
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Circle, Polygon

    ax = fig.add_axes(rect)
    lo, hi = view.lo, view.hi
    grounds, spheres = _contacts(system)
    for g in grounds:
        n = g.unit_normal
        t = np.array([-n[1], n[0]])
        p = g.height * n
        r = 2.0 * float(np.max(hi - lo)) + float(np.linalg.norm(p - 0.5 * (lo + hi)))
        quad = np.array([p - r * t, p + r * t, p + r * t - r * n, p - r * t - r * n])
        ax.add_patch(Polygon(quad, closed=True, facecolor=(0.55, 0.45, 0.35, 0.25), edgecolor="none", zorder=0))
        ax.plot(*np.array([p - r * t, p + r * t]).T, color=(0.4, 0.3, 0.2), lw=1.2, zorder=1)
    for s in spheres:
        ax.add_patch(Circle(s._c, s.radius, facecolor="0.8", edgecolor="0.4", zorder=0))
    if triangles is not None and len(triangles):
        ax.add_collection(PolyCollection(x[np.asarray(triangles)], facecolors=(*_SURFACE, 0.35),
                                         edgecolors="none", zorder=1))
    for node, colour in zip(view.tracks, ("0.35", "tab:green")):
        path = np.asarray(traj.x)[: k + 1, node]
        ax.plot(path[:, 0], path[:, 1], "-", lw=0.8, color=colour, alpha=0.4, zorder=2)
        ax.plot(*path[-1], "o", ms=3.5, color=colour, zorder=5)
    mappable = None
    if system.n_springs:
        cmap, norm = _strain_mappable(view)
        seg = np.stack([x[system.springs[:, 0]], x[system.springs[:, 1]]], axis=1)
        lc = LineCollection(seg, cmap=cmap, norm=norm, linewidths=2.0, zorder=3)
        lc.set_array(spring_strain(system, x))
        ax.add_collection(lc)
        mappable = lc
    pins = x[system.pinned]
    if len(pins):
        ax.plot(pins[:, 0], pins[:, 1], "s", ms=5, color=_PIN, zorder=6)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x", fontsize=8)
    ax.set_ylabel("y", fontsize=8)
    ax.tick_params(labelsize=8)
    return ax, mappable


def _draw_energy(fig, rect, traj, k: int, view: SceneView, marker: bool):
    ax = fig.add_axes(rect)
    es = _energy_series(traj)
    t = np.asarray(traj.times, dtype=float)
    styles = {"kinetic": ("tab:orange", "-"), "potential": ("tab:blue", "-"),
              "total": ("black", "-")}
    for key in ("total", "potential", "kinetic"):           # total underneath, others visible
        colour, ls = styles[key]
        ax.plot(t, es[key], ls, color=colour, lw=2.2 if key == "total" else 1.1, label=key,
                alpha=0.75 if key == "total" else 1.0)
    if marker:
        ax.axvline(t[k], color="0.5", lw=0.8)
        ax.plot([t[k]] * 3, [es[key][k] for key in es], "o", ms=3, color="0.3")
    stop = _stop(traj)
    if stop is not None:
        ax.axvline(stop[1], color=_PIN, ls="--", lw=1.2, label=f"unstable, step {stop[0]}")
    right = max(float(t[-1]), stop[1] if stop else 0.0)
    width = right - float(t[0]) if right > t[0] else 1.0
    ax.set_xlim(float(t[0]), float(t[0]) + width * (1.04 if stop else 1.0))
    ax.set_ylim(*view.energy_limits)
    ax.set_xlabel("t [s]", fontsize=8)
    ax.set_ylabel("energy", fontsize=8)
    ax.set_title("energy", fontsize=9)
    ax.tick_params(labelsize=8)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
    ax.yaxis.get_offset_text().set_fontsize(7)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best", frameon=False)
    return ax


def plot_frame(system, traj, frame: int = -1, *, triangles=None, name: str = "",
               view: SceneView | None = None, size: tuple[float, float] = (9.6, 4.8),
               dpi: float = 100, energy: bool = True, marker: bool = False):
    """A matplotlib :class:`~matplotlib.figure.Figure` of recorded frame ``frame`` of ``traj``.

    Parameters
    ----------
    system : MassSpringSystem
    traj : Trajectory (``times``, ``x``, ``energies``; ``completed``/``steps``/``dt`` mark an
        unstable stop).
    frame : index of the recorded frame (negative counts from the end).
    triangles : ``(m, 3)`` surface triangles (cloth, mesh) or ``None``.
    name : scene name for the title.
    view : fixed limits/colour range (default: :func:`scene_view` of every frame).
    size, dpi : figure size in inches and resolution.
    energy : draw the energy panel.
    marker : mark the current time on the energy panel (the GIF does).

    Returns
    -------
    matplotlib.figure.Figure
        ``fig.scene_axes`` is the scene axes (a 3-D axes, with ``zaxis``, for 3-D systems),
        ``fig.energy_axes`` the energy axes (or ``None``), ``fig.strain_mappable`` the
        strain-coloured spring collection (or ``None`` when a surface is drawn).
    """
    k = int(frame) % len(traj.times)
    view = view or scene_view(system, traj)
    x = np.asarray(traj.x[k], dtype=float)
    fig = new_figure(size[0], size[1], dpi=dpi)
    if system.dim == 3:
        main = [-0.03, 0.0, 0.68, 0.9] if energy else [0.0, 0.0, 0.9, 0.9]
        ax, mappable = _draw_3d(fig, main, system, x, triangles, view, name, traj, k)
        cax = fig.add_axes([0.6, 0.2, 0.012, 0.55]) if mappable else None
    else:
        main = [0.06, 0.11, 0.54, 0.76] if energy else [0.08, 0.1, 0.78, 0.78]
        ax, mappable = _draw_2d(fig, main, system, x, triangles, view, name, traj, k)
        cax = ax.inset_axes([1.03, 0.1, 0.035, 0.8]) if mappable else None
    if mappable is not None:
        cb = fig.colorbar(mappable, cax=cax)
        cb.set_label("spring strain (l - L)/L", fontsize=7)
        cb.ax.tick_params(labelsize=8)
    text, colour = _title(name, traj, k)
    fig.text(0.02, 0.975, text, fontsize=10, color=colour, va="top", ha="left")
    left = 0.75 if (mappable is not None and system.dim == 3) else 0.72
    eax = _draw_energy(fig, [left, 0.13, 0.98 - left, 0.72], traj, k, view, marker) if energy else None
    fig.scene_axes, fig.energy_axes, fig.strain_mappable = ax, eax, mappable
    return fig


def write_final_png(path: str | os.PathLike, system, traj, name: str, *, triangles=None,
                    dpi: float = 100) -> Path:
    """The last frame and the energy of the run as a PNG (see :func:`plot_frame`).

    3-D systems are framed on the final shape; 2-D ones on the whole run (the tracked paths).
    """
    from ...io.atomic import atomic_path

    frames = [len(traj.times) - 1] if system.dim == 3 else None
    view = scene_view(system, traj, frames)
    if frames is not None:                  # energy axes always cover the whole run
        view.energy_limits = scene_view(system, traj).energy_limits
    if system.n_springs:                    # colours resolve the final strain pattern
        final = np.abs(spring_strain(system, traj.x[-1]))
        view.strain_max = max(float(np.max(final[np.isfinite(final)], initial=0.0)), 1e-6)
    fig = plot_frame(system, traj, -1, triangles=triangles, name=name, view=view, dpi=dpi)
    image = _quantize([rgb_image(fig)], 256)[0]
    with atomic_path(path) as tmp:
        image.save(tmp, format="PNG", optimize=True)        # 8-bit palette: ~1/3 the bytes
    return Path(path)


#: Colours kept exactly by the palettes (pins, curves, text), whatever their pixel count.
_KEY_COLOURS = (_PIN, "#000000", "#ffffff", "tab:orange", "tab:blue", "tab:green", "0.35",
                "0.3", "#404040")


def _quantize(images, colours: int):
    """The RGB ``images`` as palette images sharing one median-cut palette of ``colours``.

    All images (plus a band of the key colours, so small markers keep their exact colour) are
    quantised together, so every pixel gets its exact nearest palette colour and the frames of
    a GIF share one palette.
    """
    from matplotlib.colors import to_rgb
    from PIL import Image

    w, h = images[0].width, images[0].height
    band = max(4, h // 10)
    keys = np.array([[round(255 * c) for c in to_rgb(name)] for name in _KEY_COLOURS], np.uint8)
    cols = np.repeat(np.arange(len(keys)), -(-w // len(keys)))[:w]
    strip = Image.new("RGB", (w, h * len(images) + band))
    for i, im in enumerate(images):
        strip.paste(im, (0, i * h))
    strip.paste(Image.fromarray(np.ascontiguousarray(np.broadcast_to(keys[cols], (band, w, 3)))),
                (0, h * len(images)))
    q = strip.quantize(colors=colours, method=Image.Quantize.MEDIANCUT)
    return [q.crop((0, i * h, w, (i + 1) * h)) for i in range(len(images))]


def write_gif(path: str | os.PathLike, system, traj, name: str, *, triangles=None,
              max_frames: int = 60, dpi: float = 100) -> Path:
    """An animated GIF of at most ``max_frames`` evenly spaced recorded frames.

    Same two panels as the PNG, with fixed axes over the whole animation and the current time
    marked on the energy panel; one shared palette; frame times from :func:`gif_frame_times`.
    """

    picks = gif_frames(len(traj.times), max_frames)
    view = scene_view(system, traj, picks)
    images = []
    for k in picks:
        fig = plot_frame(system, traj, int(k), triangles=triangles, name=name, view=view,
                         dpi=dpi, marker=True)
        images.append(rgb_image(fig))
    frames = _quantize(images, 128)
    ms = [int(round(1000 * d)) for d in gif_frame_times(traj.times, picks)]
    return save_gif(path, frames, ms)
