"""Pictures every time-dependent problem kind shares: a rendered figure as an image, which
recorded frames an animated GIF shows and for how long, and the GIF written atomically.

The scene (:mod:`femkit.case.scene.plot`) and the solid (:mod:`femkit.case.solid.plot`) draw
their own frames and hand them here. Matplotlib and Pillow are imported inside the functions
only.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["GIF_PLAYBACK", "rgb_image", "gif_frames", "gif_frame_times", "save_gif"]

#: Playback length of a GIF: simulated time is shown in real time when it lies in this range,
#: otherwise scaled into it.
GIF_PLAYBACK = (2.0, 8.0)


def rgb_image(fig):
    """The rendered figure as a Pillow RGB image."""
    from PIL import Image

    fig.canvas.draw()
    return Image.fromarray(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())


def gif_frames(n: int, max_frames: int = 60) -> np.ndarray:
    """Recorded frames a GIF shows: every ``ceil(n / max_frames)``-th one (even spacing in
    time), always the last one.

    >>> gif_frames(101, 60).size, gif_frames(6, 60).tolist()
    (51, [0, 1, 2, 3, 4, 5])
    """
    if n < 1 or max_frames < 1:
        from ..errors import InputError

        raise InputError(f"a GIF needs at least one frame (n = {n}, max_frames = {max_frames})")
    stride = -(-n // max_frames)
    picks = np.arange(0, n, stride)
    if picks[-1] != n - 1:
        picks = np.append(picks[: max_frames - 1], n - 1)
    return picks


def gif_frame_times(times: Sequence[float], picks: Sequence[int],
                    playback: tuple[float, float] = GIF_PLAYBACK) -> np.ndarray:
    """Display time (s) of each picked frame: simulated time, scaled into ``playback``.

    A run of 2-8 s plays in real time; a shorter one is slowed down to 2 s, a longer one sped
    up to 8 s. Every frame shows at least 20 ms (the GIF minimum browsers honour); the last one
    is held for 1 s, so a looping GIF pauses on the final state.

    >>> gif_frame_times([0.0, 0.5, 1.0, 3.0], [0, 1, 2]).tolist()   # 1 s of simulation -> 2 s
    [1.0, 1.0, 1.0]
    """
    t = np.asarray(times, dtype=float)[np.asarray(picks, dtype=int)]
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    total = float(np.clip(span, *playback)) if span > 0 else playback[0]
    if len(t) > 1:
        steps = np.diff(t) * (total / span) if span > 0 else np.full(len(t) - 1, total / (len(t) - 1))
        out = np.maximum(np.round(steps, 2), 0.02)
    else:
        out = np.zeros(0)
    return np.append(out, 1.0)




def save_gif(path: str | os.PathLike, frames: list, durations_ms: Sequence[int]) -> Path:
    """Write the Pillow images ``frames`` as a looping GIF at ``path`` (atomically), frame ``i``
    shown ``durations_ms[i]`` milliseconds."""
    from ..io.atomic import atomic_path

    with atomic_path(path) as tmp:
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:],
                       duration=list(durations_ms), loop=0, optimize=False, disposal=1)
    return Path(path)
