"""Pictures of a deformed solid: PNG of a frame, animated GIF of the run (matplotlib, Agg).

3D: the boundary surface of the deformed tetrahedra, each face coloured by the von Mises stress
of its element and shaded by its normal against a fixed light (a headless matplotlib render, no
OpenGL). 2D: the deformed triangles filled by von Mises stress, the rest outline in grey. Both
with a colour bar beside the body (its own axes: it never covers the tick labels), fixed axes
over a whole animation, the frame's time (or load factor) and largest displacement in the
title.

Small deformations are magnified: the body is drawn at ``X + s u`` with ``s`` from
:func:`display_scale` (a round factor that shows the largest displacement as about
:data:`SHOWN_FRACTION` of the body's size, 1 when it is already that large), and the title says
``displacement x s``; colours are the true stresses. Matplotlib and Pillow are imported inside
the functions.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

__all__ = ["surface_faces", "plot_solid_frame", "write_solid_png", "write_solid_gif",
           "display_scale", "SHOWN_FRACTION"]

#: The largest displacement a picture shows, as a fraction of the body's largest extent.
SHOWN_FRACTION = 0.15

#: Local faces of a positively oriented tetrahedron, face k opposite vertex k, outward.
_TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
_LIGHT = np.array([0.35, -0.55, 0.76])


def surface_faces(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boundary faces ``(k, 3)`` (outward) of positively oriented tetrahedra and the element
    each belongs to ``(k,)``."""
    loc = cells[:, _TET_FACES].reshape(-1, 3)
    _, inverse, counts = np.unique(np.sort(loc, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    keep = counts[inverse.ravel()] == 1
    return loc[keep], np.repeat(np.arange(len(cells)), 4)[keep]


def display_scale(u_max: float, size: float) -> float:
    """The factor a picture multiplies the displacements by: 1 when the largest displacement
    ``u_max`` is at least :data:`SHOWN_FRACTION` of the body's size, else the largest round
    number (1, 2, 2.5 or 5 times a power of ten) that keeps it below that.

    >>> display_scale(0.013, 2.0), display_scale(0.5, 2.0), display_scale(0.0, 2.0)
    (20.0, 1.0, 1.0)
    """
    if not (u_max > 0 and np.isfinite(u_max)) or u_max >= SHOWN_FRACTION * size:
        return 1.0
    want = SHOWN_FRACTION * size / u_max
    power = 10.0 ** np.floor(np.log10(want))
    return float(max(m * power for m in (1.0, 2.0, 2.5, 5.0) if m * power <= want * (1 + 1e-12)))


def _scale(result, frames) -> float:
    """:func:`display_scale` of the largest displacement over ``frames``."""
    rest = result.problem.body.rest_positions
    u_max = max(float(np.linalg.norm(result.x[k] - rest, axis=1).max()) for k in frames)
    return display_scale(u_max, float(np.ptp(rest, axis=0).max()))


def _shown(result, k: int, scale: float) -> np.ndarray:
    rest = result.problem.body.rest_positions
    return rest + scale * (result.x[k] - rest)


def _norm(result, frames):
    from matplotlib.colors import Normalize

    top = max(float(np.nanmax(result.fields(k)["von_mises"], initial=0.0)) for k in frames)
    return Normalize(0.0, top if top > 0 else 1.0)


def _limits(result, frames, scale: float = 1.0) -> np.ndarray:
    pts = np.concatenate([_shown(result, k, scale) for k in frames]
                         + [result.problem.body.rest_positions])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.04 * float(np.max(hi - lo))
    return np.stack([lo - pad, hi + pad])


def _title(result, k: int, scale: float) -> str:
    u = result.x[k] - result.problem.body.rest_positions
    when = (f"load factor {result.times[k]:.3g}" if result.case.spec.static is not None
            else f"t = {result.times[k]:.4g}")
    shown = "" if scale == 1.0 else f"\ndisplacement x {scale:g} (true stresses)"
    return f"{result.case.name}: {when}, max |u| = {np.linalg.norm(u, axis=1).max():.4g}{shown}"


def _draw_3d(fig, result, x, vm, norm, cmap, lim):
    """The deformed boundary surface over the faint rest shape, on 3D axes framing ``lim``."""
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    body = result.problem.body
    ax = fig.add_axes((0.0, 0.17, 0.94, 0.75), projection="3d")
    faces, owner = surface_faces(body.rest.cells[:, :4])      # P2: the vertex cells
    tri = x[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    shade = 0.45 + 0.55 * np.abs(n @ (_LIGHT / np.linalg.norm(_LIGHT)))
    colours = cmap(norm(vm[owner]))
    colours[:, :3] *= shade[:, None]
    ax.add_collection3d(Poly3DCollection(body.rest_positions[faces], facecolors=(0.5, 0.5, 0.5, 0.06),
                                         edgecolors=(0.4, 0.4, 0.4, 0.08), linewidths=0.2))
    ax.add_collection3d(Poly3DCollection(tri, facecolors=colours, edgecolors=(0, 0, 0, 0.15),
                                         linewidths=0.2))
    extent = lim[1] - lim[0]
    for axis, e in zip((ax.xaxis, ax.yaxis, ax.zaxis), extent):
        # a thin side of the body gets fewer ticks: its labels would run into each other
        axis.set_major_locator(MaxNLocator(int(np.clip(round(5 * e / extent.max()), 1, 4))))
    ax.set_xlim(*lim[:, 0]), ax.set_ylim(*lim[:, 1]), ax.set_zlim(*lim[:, 2])
    ax.set_box_aspect(np.maximum(extent, 1e-9 * extent.max()), zoom=1.2)
    ax.view_init(elev=22, azim=-60)
    ax.set_xlabel("x"), ax.set_ylabel("y"), ax.set_zlabel("z")
    return ax


def _draw_2d(fig, result, x, vm, norm, cmap, lim):
    """Filled deformed triangles over the rest outline."""
    from matplotlib.collections import LineCollection

    from ...mesh.edges import boundary_edges_topological

    body = result.problem.body
    ax = fig.add_axes((0.1, 0.25, 0.85, 0.62))
    outline = body.rest_positions[boundary_edges_topological(result.problem.mesh)]
    ax.add_collection(LineCollection(outline, colors="0.6", linewidths=0.6))
    ax.tripcolor(x[:, 0], x[:, 1], body.rest.cells[:, :3], facecolors=vm, cmap=cmap, norm=norm,
                 edgecolors="k", linewidth=0.1)
    ax.set_xlim(*lim[:, 0]), ax.set_ylim(*lim[:, 1])
    ax.set_aspect("equal")
    ax.set_xlabel("x"), ax.set_ylabel("y")
    return ax


def plot_solid_frame(result, k: int = -1, *, norm=None, limits=None, scale: float | None = None,
                     dpi: float = 100):
    """A figure of frame ``k`` of a :class:`~femkit.case.solid.run.SolidResult`, its
    displacement times ``scale`` (default :func:`display_scale` of the frame)."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable

    from ...io.figures import new_figure

    k = k % len(result.x)
    scale = _scale(result, [k]) if scale is None else float(scale)
    x = _shown(result, k, scale)
    vm = np.nan_to_num(result.fields(k)["von_mises"], nan=0.0)
    norm = norm or _norm(result, [k])
    lim = _limits(result, [k], scale) if limits is None else limits
    cmap = colormaps["viridis"]
    fig = new_figure(7.0, 5.0, dpi=dpi)
    draw = _draw_3d if result.problem.body.dim == 3 else _draw_2d
    ax = draw(fig, result, x, vm, norm, cmap, lim)
    # the colour bar in its own axes below the body: clear of every tick label
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), orientation="horizontal",
                       cax=fig.add_axes((0.25, 0.12, 0.5, 0.03)), label="von Mises stress")
    bar.ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
    fig.suptitle(_title(result, k, scale) + ("  (rest shape in grey)" if ax.name != "3d" else ""),
                 fontsize=10, y=0.97)
    return fig


def write_solid_png(path: str | os.PathLike, result, k: int = -1) -> Path:
    """PNG of frame ``k`` (default the last)."""
    from ...io.figures import save_figure

    return save_figure(plot_solid_frame(result, k), path)


def write_solid_gif(path: str | os.PathLike, result, *, max_frames: int = 40,
                    dpi: float = 80) -> Path:
    """Animated GIF of at most ``max_frames`` evenly spaced frames, fixed axes, colour scale and
    displacement factor (:func:`display_scale` of the largest displacement of those frames)."""
    from ..pictures import gif_frame_times, gif_frames, rgb_image, save_gif

    picks = gif_frames(len(result.x), max_frames)
    scale = _scale(result, picks)
    norm, lim = _norm(result, picks), _limits(result, picks, scale)
    images = [rgb_image(plot_solid_frame(result, int(k), norm=norm, limits=lim, scale=scale,
                                          dpi=dpi))
              for k in picks]
    frames = [im.quantize(colors=128) for im in images]
    ms = [int(round(1000 * d)) for d in gif_frame_times(result.times, picks)]
    return save_gif(path, frames, ms)
