"""The solid kind's picture (:attr:`femkit.kinds.Kind.view` of ``problem: solid``): the body
warped by its displacement, coloured by the von Mises stress (or ``J``, the displacement's or
the velocity's length), the rest shape as a translucent ghost; one frame per recorded load or
time step (``solid.pvd``), so a movie shows the loading or the motion. pyvista: ``femkit[view]``.
"""

from __future__ import annotations

import numpy as np

from ...view.core import Frame, Layer, Picture
from ...view.core.generic import colour_by, field_names, read_series, surface
from ...view.core.source import Run, check_field

__all__ = ["solid_view"]

#: The colour bar's title of each field (the units are those of the case file: E's for stress).
TITLES = {"von_mises": "von Mises stress (units of E)", "J": "J = det F",
          "displacement": "|displacement| (length units)", "velocity": "|velocity|",
          "region": "region"}


def _scale(frames, requested: float | None) -> float:
    """The displacement's magnification: ``requested``, else 1 unless the largest displacement
    is below 2 % of the body's size, then what makes it 10 % (a round number)."""
    if requested is not None:
        return float(requested)
    size = float(np.linalg.norm(np.ptp(np.asarray(frames[0][1].points), axis=0))) or 1.0
    largest = max(float(np.abs(np.asarray(m["displacement"])).max(initial=0.0)) for _, m in frames)
    if largest <= 0 or largest >= 0.02 * size:
        return 1.0
    factor = 0.1 * size / largest
    return float(10 ** np.floor(np.log10(factor)))


def solid_view(run: Run, field: str | None = None, scale: float | None = None,
               frames: int = 60, edges: bool | None = None) -> Picture:
    """The picture of a solid run (from its run directory: ``solid.pvd`` and its frames).

    Parameters
    ----------
    run : Run
        The result (with its output directory) or the run directory.
    field : str, optional
        ``von_mises`` (default), ``J``, ``displacement``, ``velocity``, ``region``.
    scale : float, optional
        The displacement's magnification (default: 1, or a power of ten when the displacement
        is too small to see; the title says which).
    frames : int
        At most this many frames (evenly spaced, the last included).
    edges : bool, optional
        Draw the element edges (default: when each face gets 20 x 20 pixels on average).
    """
    series = read_series(run.file("solid.pvd"), frames)
    rest = series[0][1]
    fields = [n for n in field_names(rest) if n != "principal_stretches"]
    name = check_field(field, fields, "von_mises")
    factor = _scale(series, scale)
    dim = 2 if rest.get_cell(0).type == 5 else 3  # VTK_TRIANGLE: a plane-strain body
    ghost = Layer(surface(rest), color="grey", opacity=0.2)
    out = []
    for t, mesh in series:
        shown = mesh.warp_by_vector("displacement", factor=factor)
        scalars = colour_by(shown, name)
        body = surface(shown) if dim == 3 else shown
        out.append(Frame([Layer(body, scalars, TITLES.get(name, name), edges=edges,
                                cmap="turbo" if name == "von_mises" else "viridis"), ghost], t))
    shown_as = "" if factor == 1 else f", displacement x {factor:g}"
    title = f"{run.name}: {TITLES.get(name, name).split(' (')[0]}{shown_as}"
    facts = run.facts or (run.result.to_dict() if run.result is not None else {})
    label = "load factor" if facts.get("mode") == "static" else "t"
    return Picture(out, title=title, dim=dim, field=name, fields=tuple(fields), time_label=label)
