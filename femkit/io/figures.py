"""The one figure helper: a matplotlib Figure on the Agg canvas (no pyplot state, no display)
and its atomic save. matplotlib is imported only when a figure is made."""

from __future__ import annotations

import os
from pathlib import Path

from .atomic import atomic_path

__all__ = ["new_figure", "save_figure", "DPI"]

#: Resolution of every PNG femkit writes unless a caller asks for another.
DPI = 100


def new_figure(width: float = 7.0, height: float = 5.0, *, dpi: float = DPI, layout: str | None = None):
    """A ``matplotlib.figure.Figure`` of ``width x height`` inches with an Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=dpi, layout=layout)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig, path: str | os.PathLike, *, dpi: float | None = None) -> Path:
    """Save ``fig`` as PNG at ``path`` atomically (parent directories created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi or fig.dpi, format="png")
    return path
