"""The picture of a study's output directory (what ``femkit study`` writes): one of the
report's figures, shown as the image it is.

A study keeps no run directories, only its report (``report.md``, ``report.html``), its numbers
(``results.json``, ``runs.csv``) and its figures (``figures/*.png``, drawn by matplotlib). So
the study's picture is its report's principal figure: the first one the report shows
(``results.json``'s ``figures``, in the report's order; for a convergence study the error
against the mesh size, for a work-precision study the error against the unknowns or the run
time). ``field`` picks another figure by its name (the file's stem: ``work_precision``). One
mechanism for every study kind: the figures are read from the directory, nothing per kind.
"""

from __future__ import annotations

import json
from pathlib import Path

from ...errors import InputError
from .picture import Frame, Layer, Picture
from .render import pyvista
from .source import check_field

__all__ = ["is_study_dir", "study_figures", "study_picture"]

#: What marks a study's output directory (``femkit.study.run``).
STUDY_FILE = "results.json"


def is_study_dir(path: Path) -> bool:
    """Whether ``path`` is a study's output directory (a ``results.json`` beside ``report.md``,
    no run's ``result.json``)."""
    return (path.is_dir() and (path / STUDY_FILE).is_file() and (path / "report.md").is_file()
            and not (path / "result.json").is_file())


def study_figures(path: Path) -> tuple[str, dict, dict[str, Path]]:
    """The study's name, its ``results.json`` and its figures (name -> PNG file), in the
    report's order.

    Raises
    ------
    InputError
        ``results.json`` is unreadable, or the study wrote no figure.
    """
    meta = path / STUDY_FILE
    try:
        facts = json.loads(meta.read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{meta}: unreadable ({exc})") from None
    listed = facts.get("figures") if isinstance(facts, dict) else None
    files = [path / f for f in listed] if isinstance(listed, list) else \
        sorted((path / "figures").glob("*.png"))
    figures = {f.stem: f for f in files if f.is_file()}
    name = str(facts.get("name", path.name)) if isinstance(facts, dict) else path.name
    if not figures:
        raise InputError(f"{path}: the study {name!r} wrote no figure to draw (its report is "
                         "tables only: report.md)")
    return name, facts, figures


def study_picture(path: Path, field: str | None = None) -> Picture:
    """The figure ``field`` (default: the report's first) of the study output ``path``, as an
    image layer (its own colours, no axes, no colour bar)."""
    name, facts, figures = study_figures(path)
    chosen = check_field(field, tuple(figures), next(iter(figures)))
    image = pyvista().read(figures[chosen])
    colours = next(iter(image.point_data.keys()))
    layer = Layer(image, scalars=colours, rgb=True, lighting=False, edges=False)
    kind = str(facts.get("kind", "study"))
    title = f"{name}: {chosen}" + ("" if kind == name else f" ({kind})")
    return Picture([Frame([layer])], title=title, dim=2, field=chosen,
                   fields=tuple(figures), axes=False)
