""":class:`View`: a picture a notebook shows inline (a PNG, or an animated GIF for a time series,
rendered off screen: no server, no widget), saved with :meth:`View.screenshot` and
:meth:`View.movie`, opened in a window with :meth:`View.show`, or a time series with a frame
slider in the notebook (:meth:`View.slider`, ipywidgets)."""

from __future__ import annotations

import base64
import os
from pathlib import Path

from .picture import Picture

__all__ = ["View"]


class View:
    """A picture of a run, drawn on demand.

    Parameters
    ----------
    picture : Picture
        What :func:`femkit.view.core.dispatch.picture_of` built.
    size : tuple of int
        Width and height in pixels of the inline image.
    frame : int, optional
        The frame shown inline (a PNG) and by :meth:`screenshot`; None (the default): a time
        series shows inline as an animation, and its screenshot is the last frame.
    """

    def __init__(self, picture: Picture, size: tuple[int, int] = (960, 720),
                 frame: int | None = None):
        self.picture = picture
        self.size = tuple(size)
        self.animated = frame is None and len(picture.frames) > 1
        self.frame_index = -1 if frame is None else frame

    @property
    def fields(self) -> tuple[str, ...]:
        """The fields the source offers."""
        return self.picture.fields

    def frame(self, index: int) -> "View":
        """The same view showing frame ``index`` (a time series' instant; an InputError names
        the valid range)."""
        from .render import frame_index

        return View(self.picture, self.size, frame_index(self.picture, index))

    def image(self):
        """The frame as an ``(height, width, 3)`` RGB array."""
        from .render import image

        return image(self.picture, self.frame_index, self.size)

    def screenshot(self, path: str | os.PathLike, size: tuple[int, int] | None = None) -> Path:
        """Write the frame to the PNG ``path`` (atomically); returns it."""
        from .render import screenshot

        return screenshot(self.picture, path, self.frame_index, size or self.size)

    def movie(self, path: str | os.PathLike, size: tuple[int, int] | None = None,
              fps: float = 10.0) -> Path:
        """Write every frame to the movie ``path`` (``.gif``, ``.mp4``); returns it."""
        from .render import movie

        return movie(self.picture, path, size or self.size, fps)

    def slider(self, size: tuple[int, int] | None = None):
        """A notebook widget: the frames with a slider (``ipywidgets``; each frame rendered off
        screen when first shown; :func:`femkit.view.core.widget.slider_widget`)."""
        from .widget import slider_widget

        return slider_widget(self.picture, size or self.size)

    def show(self) -> None:
        """Open an interactive window (a frame slider for a time series)."""
        from .render import show

        show(self.picture, self.frame_index, self.size)

    def _repr_png_(self) -> bytes | None:
        if self.animated:
            return None  # shown as an animation by _repr_html_
        from .render import png_bytes

        return png_bytes(self.picture, self.frame_index, self.size)

    def _repr_html_(self) -> str | None:
        """A time series inline: an animated GIF (every frame, one colour range)."""
        if not self.animated:
            return None
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            path = self.movie(Path(tmp) / "frames.gif", size=(640, 480))
            data = base64.b64encode(path.read_bytes()).decode("ascii")
        return (f'<img src="data:image/gif;base64,{data}" alt="{self.picture.title}" '
                f'style="max-width: 100%"/>')

    def __repr__(self) -> str:
        return (f"View({self.picture.title!r}, field={self.picture.field!r}, "
                f"frames={len(self.picture.frames)}, fields={list(self.picture.fields)})")
