"""What a picture is made of, as data: :class:`Layer`, :class:`Frame`, :class:`Picture`.

A kind's view function (:attr:`femkit.kinds.Kind.view`) builds a :class:`Picture` from a result
object or a run directory; :mod:`femkit.view.core.render` draws any picture with pyvista (on
screen, off screen, into a PNG, a GIF or an MP4, inline in a notebook). Nothing here imports
pyvista: the meshes a layer holds are pyvista datasets made by the view functions, which import
pyvista through :func:`femkit.view.core.render.pyvista` (the optional extra ``femkit[view]``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Layer", "Frame", "Picture"]


@dataclass
class Layer:
    """One dataset drawn one way.

    Parameters
    ----------
    mesh : pyvista.DataSet
        What is drawn.
    scalars : str, optional
        The array the layer is coloured by (point or cell data of ``mesh``); None: one colour.
    title : str, optional
        The colour bar's title, with the units (``"u"``, ``"von Mises stress (units of E)"``).
    color : str
        The colour of a layer without ``scalars`` (a ghost, an obstacle).
    opacity : float
        1 opaque, 0.15 a ghost.
    style : str
        ``"surface"``, ``"wireframe"`` or ``"points"``.
    edges : bool, optional
        Draw the cell edges over the surface; None: when each cell gets at least 20 x 20 pixels
        of the window on average (decided when drawn, by the window's size).
    log : bool
        Logarithmic colour scale (error indicators).
    cmap : str
        A matplotlib colour map name.
    point_size, line_width : float
        Sizes of points and lines (pixels).
    tubes : bool
        Draw lines as tubes and points as spheres (ropes, pins).
    lighting : bool, optional
        Shade by the lights (default: in 3D); False draws the colour map's own colours (a scalar
        field read by its colours).
    rgb : bool
        ``scalars`` are the colours themselves (RGB or RGBA bytes: an image, a study's figure),
        drawn as they are, without a colour map or a colour bar.
    """

    mesh: Any
    scalars: str | None = None
    title: str | None = None
    color: str = "lightgrey"
    opacity: float = 1.0
    style: str = "surface"
    edges: bool | None = False
    log: bool = False
    cmap: str = "viridis"
    point_size: float = 6.0
    line_width: float = 2.0
    tubes: bool = False
    lighting: bool | None = None
    rgb: bool = False


@dataclass
class Frame:
    """The layers of one instant (a time series has one frame per recorded time)."""

    layers: list[Layer]
    time: float | None = None


@dataclass
class Picture:
    """A picture: frames sharing one title, camera and colour range.

    Parameters
    ----------
    frames : list of Frame
        One (a steady field) or more (a time series; :func:`~femkit.view.core.render.movie`).
    title : str
        Drawn at the top (the case, what is shown, the mesh size).
    dim : int
        2: looked at from +z with the x and y axes; 3: an isometric view.
    field : str
        The field shown.
    fields : tuple of str
        Every field the source offers (``--field`` is checked against them).
    camera : tuple, optional
        A camera position ``(eye, focus, up)`` replacing the default view.
    clim : tuple of float, optional
        The colour range; None: the range over every frame.
    time_label : str
        What a frame's time is called under the picture (``t``; a static solid: ``load factor``).
    axes : bool
        Draw the axes (2D: x and y rulers; 3D: the orientation triad); False for an image that
        has its own (a study's figure).
    """

    frames: list[Frame]
    title: str
    dim: int
    field: str
    fields: tuple[str, ...]
    camera: tuple | None = None
    clim: tuple[float, float] | None = None
    time_label: str = "t"
    axes: bool = True

    @property
    def times(self) -> list[float | None]:
        """The time of each frame."""
        return [f.time for f in self.frames]
