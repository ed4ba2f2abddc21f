"""A time series in a Jupyter notebook with a frame slider: an ``ipywidgets`` ``IntSlider``
over the frames and an ``Image`` of the frame it points at, rendered off screen on first use
and kept (:class:`FrameImages`). No server and no pyvista widget backend: the kernel renders,
the notebook shows PNG bytes. ipywidgets is part of the optional extra ``femkit[view]``
(``pip install femkit[view]``).
"""

from __future__ import annotations

from typing import Any

from ...errors import ViewUnavailableError
from .picture import Picture

__all__ = ["FrameImages", "slider_widget"]


class FrameImages:
    """The frames of a picture as PNG bytes, each rendered when first asked for, then kept.

    Every frame is drawn in the colour range of the whole series; in 3D with the camera of the
    first frame (:func:`~femkit.view.core.render.series_camera`, as a movie), in 2D with the
    view every frame has (the bounds of all frames), so a 2D frame is the picture
    ``View.frame(k)`` shows.

    Parameters
    ----------
    picture : Picture
        The time series.
    size : tuple of int
        Width and height of each image in pixels.
    """

    def __init__(self, picture: Picture, size: tuple[int, int] = (640, 480)):
        self.picture = picture
        self.size = (int(size[0]), int(size[1]))
        self.rendered = 0  # frames rendered so far (each at most once)
        self._camera: tuple | None = None
        self._png: dict[int, bytes] = {}

    def __len__(self) -> int:
        return len(self.picture.frames)

    def png(self, frame: int) -> bytes:
        """Frame ``frame`` (negative: from the end) as PNG bytes; an InputError names the range."""
        from .render import encode_png, frame_index, image, series_camera

        k = frame_index(self.picture, frame) % len(self)
        if k not in self._png:
            if self.picture.dim == 3 and self._camera is None:
                self._camera = series_camera(self.picture, self.size)
            self._png[k] = encode_png(image(self.picture, k, self.size, camera=self._camera))
            self.rendered += 1
        return self._png[k]

    def label(self, frame: int) -> str:
        """What the slider says of frame ``frame``: its time, or its number."""
        t = self.picture.frames[frame].time
        return f"{self.picture.time_label} = {t:.4g}" if t is not None else f"frame {frame}"


def slider_widget(picture: Picture, size: tuple[int, int] = (640, 480)) -> Any:
    """An ``ipywidgets.VBox``: the image of the frame the slider points at (first the last
    frame), the slider (``IntSlider``, 0 to the last frame) and the frame's time beside it.

    Moving the slider renders the frame off screen the first time and shows it
    (:class:`FrameImages`, kept as the box's ``frames``); ``box.children`` are
    ``(Image, HBox(IntSlider, Label))``.

    Raises
    ------
    ViewUnavailableError
        ipywidgets cannot be imported; the message names ``pip install femkit[view]``.
    """
    try:
        import ipywidgets as widgets
    except ImportError as exc:
        raise ViewUnavailableError(f"the frame slider needs ipywidgets ({exc}): pip install "
                                   "femkit[view]") from None
    frames = FrameImages(picture, size)
    last = len(frames) - 1
    img = widgets.Image(value=frames.png(last), format="png", width=frames.size[0],
                        height=frames.size[1])
    slider = widgets.IntSlider(value=last, min=0, max=last, step=1, description="frame",
                               continuous_update=False)
    label = widgets.Label(frames.label(last))

    def show(change: dict) -> None:
        k = int(change["new"])
        img.value = frames.png(k)
        label.value = frames.label(k)

    slider.observe(show, names="value")
    box = widgets.VBox([img, widgets.HBox([slider, label])])
    box.frames = frames
    return box
