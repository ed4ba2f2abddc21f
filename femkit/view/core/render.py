"""Draw a :class:`~femkit.view.core.picture.Picture` with pyvista: on screen, off screen, into a
PNG, a GIF or an MP4.

pyvista is the optional extra ``femkit[view]`` (``pip install femkit[view]``); it is imported
here, on the first picture, never when femkit starts (:func:`pyvista`). Without a display
(``DISPLAY``/``WAYLAND_DISPLAY`` unset on Linux) pictures are rendered off screen, which VTK does
through EGL or OSMesa (Debian: ``libegl1``; ``scripts/install-view.sh``). VTK's warning that it
found no X server is silenced: the picture is drawn off screen all the same.

Every file is written atomically (:func:`femkit.io.atomic.atomic_path`): a PNG, a GIF or an MP4
appears whole or not at all.
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError, ViewUnavailableError
from .picture import Picture

__all__ = ["pyvista", "display_available", "offscreen_available", "plotter", "draw", "image",
           "series_camera", "encode_png", "png_bytes", "screenshot", "movie", "show", "check_movie_path", "frame_index",
           "frame_slider", "plane_bounds", "colour_range", "MOVIE_SUFFIXES",
           "INSTALL_VIEW", "INSTALL_OFFSCREEN"]

#: What the one line says when pyvista cannot be imported.
INSTALL_VIEW = "pip install femkit[view]"
#: What the one line says when there is neither a display nor off-screen OpenGL.
INSTALL_OFFSCREEN = ("EGL or OSMesa for off-screen OpenGL (Debian/Ubuntu: apt-get install libegl1 "
                     "libgl1, or scripts/install-view.sh), or run where a display is")
#: Movie formats by suffix -> what writes them.
MOVIE_SUFFIXES = {".gif": "imageio", ".mp4": "imageio-ffmpeg"}

BACKGROUND = "white"
FOREGROUND = "black"


def pyvista() -> Any:
    """The pyvista module, VTK's warnings silenced (the extra ``femkit[view]``).

    Raises
    ------
    ViewUnavailableError
        pyvista cannot be imported; the message names ``pip install femkit[view]``.
    """
    if "pyvista" in sys.modules and sys.modules["pyvista"] is None:  # hidden (tests)
        raise ViewUnavailableError(f"pictures need pyvista, which is not installed: {INSTALL_VIEW}")
    try:
        import pyvista as pv
        from vtkmodules.vtkCommonCore import vtkObject
    except ImportError as exc:
        raise ViewUnavailableError(f"pictures need pyvista, which cannot be imported here ({exc}): "
                                   f"{INSTALL_VIEW}") from None
    vtkObject.GlobalWarningDisplayOff()  # "bad X server connection" on a headless machine
    if hasattr(pv, "vtk_verbosity"):
        pv.vtk_verbosity("off")
    return pv


def display_available() -> bool:
    """Whether a window can be opened here (macOS and Windows always; elsewhere a ``DISPLAY``
    or ``WAYLAND_DISPLAY``)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def offscreen_available() -> bool:
    """Whether VTK can render without a display: an EGL or OSMesa library is installed."""
    return display_available() or any(ctypes.util.find_library(n) for n in ("EGL", "OSMesa"))


def plotter(size: tuple[int, int], off_screen: bool = True) -> Any:
    """A pyvista plotter of ``size`` pixels (width, height), white, off screen unless asked.

    Raises
    ------
    ViewUnavailableError
        pyvista is missing, or a picture is asked off screen where there is neither a display
        nor EGL/OSMesa (the message names what to install).
    """
    pv = pyvista()
    if off_screen and not offscreen_available():
        raise ViewUnavailableError("no display and no off-screen OpenGL here: install "
                                   f"{INSTALL_OFFSCREEN}")
    p = pv.Plotter(off_screen=off_screen, window_size=list(size), lighting="three lights")
    p.set_background(BACKGROUND)
    return p


def _main_layer(picture: Picture) -> int | None:
    """Index of the first layer coloured by an array (the one with the colour bar)."""
    for i, layer in enumerate(picture.frames[0].layers):
        if layer.scalars is not None and not layer.rgb:
            return i
    return None


def colour_range(picture: Picture) -> tuple[float, float] | None:
    """The colour range of the main layer over every frame (positive values only when log)."""
    i = _main_layer(picture)
    if picture.clim is not None or i is None:
        return picture.clim
    values = []
    for frame in picture.frames:
        layer = frame.layers[i]
        v = np.asarray(layer.mesh[layer.scalars], dtype=float).ravel()
        v = v[np.isfinite(v) & ((v > 0) if layer.log else True)]
        values.append(v)
    v = np.concatenate(values) if values else np.zeros(0)
    if not v.size:
        return (1e-12, 1.0) if picture.frames[0].layers[i].log else (0.0, 1.0)
    lo, hi = float(v.min()), float(v.max())
    if hi <= lo:
        hi = lo + max(abs(lo), 1.0) * 1e-6
    return lo, hi


def draw(p: Any, picture: Picture, index: int = -1, *, clim=None, camera: bool = True) -> None:
    """Add frame ``index`` of ``picture`` to plotter ``p``: its layers, the colour bar of the
    main layer (vertical, at the right), the title, the time and the axes; ``camera``: set the
    view too (2D: from +z; 3D: isometric, or the picture's own camera), else keep ``p``'s (the
    later frames of a movie, the slider)."""
    frame = picture.frames[index]
    main = _main_layer(picture)
    size = p.window_size
    font = max(10, int(size[1] / 40))
    clim = colour_range(picture) if clim is None else clim
    for i, layer in enumerate(frame.layers):
        edges = layer.edges if layer.edges is not None else \
            layer.mesh.n_cells * 400 <= size[0] * size[1]
        kwargs = dict(style=layer.style, opacity=layer.opacity, show_edges=edges,
                      point_size=layer.point_size, line_width=layer.line_width,
                      render_lines_as_tubes=layer.tubes, render_points_as_spheres=layer.tubes,
                      edge_color="#404040",
                      lighting=picture.dim == 3 if layer.lighting is None else layer.lighting)
        if layer.scalars is None:
            p.add_mesh(layer.mesh, color=layer.color, **kwargs)
            continue
        if layer.rgb:  # an image: its own colours
            p.add_mesh(layer.mesh, scalars=layer.scalars, rgb=True, show_scalar_bar=False, **kwargs)
            continue
        title = layer.title or layer.scalars
        bar = dict(title=title, vertical=True, position_x=0.84, position_y=0.1, width=0.05,
                   height=0.75, color=FOREGROUND, fmt="%.3g",
                   title_font_size=_fit(font, title, 0.26 * size[0]),
                   label_font_size=int(font * 0.85), n_labels=5)
        p.add_mesh(layer.mesh, scalars=layer.scalars, cmap=layer.cmap, log_scale=layer.log,
                   clim=clim if i == main else None, show_scalar_bar=i == main,
                   scalar_bar_args=bar, **kwargs)
    p.add_text(picture.title, position="upper_edge", color=FOREGROUND,
               font_size=_fit(int(font * 0.75), picture.title, 0.95 * size[0]))
    if frame.time is not None and len(picture.frames) > 1:
        p.add_text(f"{picture.time_label} = {frame.time:.4g}", font_size=int(font * 0.7),
                   position=(int(0.76 * size[0]), int(0.02 * size[1])), color=FOREGROUND)
    _camera(p, picture, move=camera)


def _fit(font: int, text: str, width: float) -> int:
    """``font`` (points), made smaller when ``text`` would be wider than ``width`` pixels (a
    character is about 0.75 of the font size wide in VTK's Arial, one point a pixel)."""
    return max(6, min(font, int(width / (0.75 * max(len(text), 1)))))


def plane_bounds(picture: Picture) -> list[float]:
    """The x and y range of every layer of every frame of a 2D picture, padded so that neither
    side is under 40 % of the other (a straight rope is not a line), as
    ``[x0, x1, y0, y1, 0, 0]``."""
    b = np.array([layer.mesh.bounds for frame in picture.frames for layer in frame.layers])
    lo, hi = np.array([b[:, 0].min(), b[:, 2].min()]), np.array([b[:, 1].max(), b[:, 3].max()])
    span = max(float(np.max(hi - lo)), 1e-12)
    grow = np.maximum(0.0, 0.4 * span - (hi - lo)) / 2
    lo, hi = lo - grow, hi + grow
    return [lo[0], hi[0], lo[1], hi[1], 0.0, 0.0]


def _camera(p: Any, picture: Picture, move: bool = True) -> None:
    """The axes (2D: x and y rulers around the bounds of every frame; 3D: the orientation
    triad) and, with ``move``, the view: from +z in 2D, isometric in 3D, or the picture's own."""
    bounds = plane_bounds(picture) if picture.dim == 2 else None
    if move:
        if picture.camera is not None:
            p.camera_position = picture.camera
        elif picture.dim == 2:
            p.view_xy()
            p.reset_camera(bounds=bounds)
            if not picture.axes:  # an image: fitted to the window, below the title
                _fit_image(p, bounds)
                return
        else:
            p.view_isometric()
        p.camera.zoom(0.95 if picture.dim == 3 else 0.9)
    if not picture.axes:
        return
    if picture.dim == 2:
        p.show_bounds(bounds=bounds, xtitle="x", ytitle="y", ztitle="", color=FOREGROUND,
                      location="outer", font_size=max(8, int(p.window_size[1] / 55)), n_zlabels=0,
                      grid=False, show_zaxis=False, show_zlabels=False)
    elif move:
        p.add_axes(color=FOREGROUND, line_width=2)


def _fit_image(p: Any, bounds: list[float]) -> None:
    """A parallel projection from +z in which the plane ``bounds`` fills the window's width or
    91 % of its height, whichever binds (the top strip is the title's)."""
    width, height = bounds[1] - bounds[0], bounds[3] - bounds[2]
    aspect = p.window_size[0] / p.window_size[1]
    p.enable_parallel_projection()
    p.camera.parallel_scale = 0.5 * max(height / 0.91, width / aspect)
    x, y = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    y += 0.09 * p.camera.parallel_scale  # the image's centre: the lower 91 %'s centre
    p.camera.focal_point = (x, y, 0.0)
    p.camera.position = (x, y, max(width, height))


def frame_index(picture: Picture, frame: int) -> int:
    n = len(picture.frames)
    if not -n <= frame < n:
        raise InputError(f"frame {frame} out of range: the picture has {n} frame(s) (0 to {n - 1}, "
                         "or -1 for the last)")
    return frame


def image(picture: Picture, frame: int = -1, size: tuple[int, int] = (1280, 960), *,
          camera: tuple | None = None) -> np.ndarray:
    """Frame ``frame`` rendered off screen: an ``(height, width, 3)`` array of RGB bytes, in the
    colour range of every frame; ``camera`` (a pyvista camera position) replaces the frame's
    own view (a time series drawn with one camera: :func:`series_camera`)."""
    p = plotter(size, off_screen=True)
    try:
        draw(p, picture, frame_index(picture, frame))
        if camera is not None:
            p.camera_position = camera
        return np.asarray(p.screenshot(None, return_img=True))
    finally:
        p.close()


def series_camera(picture: Picture, size: tuple[int, int]) -> tuple:
    """The camera position of the first frame of ``picture`` drawn at ``size``: the one view of
    every frame of a movie and of the notebook's slider."""
    p = plotter(size, off_screen=True)
    try:
        draw(p, picture, 0)
        return tuple(p.camera_position)
    finally:
        p.close()


def encode_png(img: np.ndarray) -> bytes:
    """An RGB array as PNG bytes."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")  # optimize=True: 5x the time for 5 % fewer bytes
    return buf.getvalue()


def png_bytes(picture: Picture, frame: int = -1, size: tuple[int, int] = (1280, 960)) -> bytes:
    """Frame ``frame`` as PNG bytes (what a notebook shows inline)."""
    return encode_png(image(picture, frame, size))


def screenshot(picture: Picture, path: str | os.PathLike, frame: int = -1,
               size: tuple[int, int] = (1280, 960)) -> Path:
    """Write frame ``frame`` (default: the last) to the PNG ``path`` atomically; returns it."""
    from ...io.atomic import atomic_write_bytes

    path = Path(path)
    if path.suffix.lower() != ".png":
        raise InputError(f"--screenshot {path}: a screenshot is a .png file")
    return atomic_write_bytes(path, png_bytes(picture, frame, size))


def check_movie_path(path: Path) -> None:
    suffix = path.suffix.lower()
    if suffix not in MOVIE_SUFFIXES:
        raise InputError(f"--movie {path}: unknown movie format {suffix or '(none)'!r}; valid: "
                         + ", ".join(MOVIE_SUFFIXES))
    if suffix == ".mp4":
        import importlib.util

        if importlib.util.find_spec("imageio_ffmpeg") is None:
            raise ViewUnavailableError(f"--movie {path}: MP4 needs imageio-ffmpeg: pip install "
                                       "imageio-ffmpeg (or write a .gif)")


def movie(picture: Picture, path: str | os.PathLike, size: tuple[int, int] = (800, 600),
          fps: float = 10.0) -> Path:
    """Write every frame of ``picture`` to the movie ``path`` (``.gif``; ``.mp4`` with
    imageio-ffmpeg) atomically, one camera and one colour range for all frames; returns it."""
    import imageio.v2 as imageio

    from ...io.atomic import atomic_path

    path = Path(path)
    check_movie_path(path)
    clim = colour_range(picture)
    p = plotter(size, off_screen=True)
    images = []
    try:
        for k in range(len(picture.frames)):
            camera = p.camera_position if k else None
            p.clear()
            draw(p, picture, k, clim=clim, camera=k == 0)
            if camera is not None:
                p.camera_position = camera
            images.append(np.asarray(p.screenshot(None, return_img=True)))
    finally:
        p.close()
    with atomic_path(path) as tmp:
        if path.suffix.lower() == ".gif":
            imageio.mimsave(tmp, images, format="GIF", duration=1000.0 / fps, loop=0)
        else:  # H.264 in yuv420p: even sides, kept as drawn (no resize, no warning)
            imageio.mimsave(tmp, [_even(img) for img in images], fps=fps, macro_block_size=2)
    return path


def _even(img: np.ndarray) -> np.ndarray:
    """``img`` with a white row and column appended where its height or width is odd."""
    h, w = img.shape[:2]
    return np.pad(img, ((0, h % 2), (0, w % 2), (0, 0)), constant_values=255)


def show(picture: Picture, frame: int = -1, size: tuple[int, int] = (1024, 768)) -> None:
    """Open an interactive window on frame ``frame`` (a slider over the frames of a time
    series); where there is no display, :class:`ViewUnavailableError` says so."""
    if not display_available():
        raise ViewUnavailableError("no display here for an interactive window: give --screenshot "
                                   "FILE or --movie FILE to render off screen")
    p = plotter(size, off_screen=False)
    draw(p, picture, frame_index(picture, frame))
    if len(picture.frames) > 1:
        p.add_slider_widget(frame_slider(p, picture), [0, len(picture.frames) - 1],
                            value=len(picture.frames) - 1, title="frame", fmt="%.0f",
                            pointa=(0.1, 0.06), pointb=(0.6, 0.06))
    p.show()


def frame_slider(p: Any, picture: Picture):
    """The slider's callback of :func:`show`: ``go(value)`` redraws plotter ``p`` at frame
    ``round(value)``, keeping the camera and the colour range of the whole series."""
    clim = colour_range(picture)

    def go(value: float) -> None:
        camera = p.camera_position
        p.clear()  # actors, colour bar, texts
        draw(p, picture, int(round(value)), clim=clim, camera=False)
        p.camera_position = camera

    return go
