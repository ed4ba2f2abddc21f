"""The dispatch of a picture to its kind's view function, through :data:`femkit.kinds.KINDS`
(:attr:`femkit.kinds.Kind.view`); a kind without one is drawn from its files
(:func:`femkit.view.core.generic.generic_picture`); a study's output directory is drawn as its
report's figure (:func:`femkit.view.core.study.study_picture`, the same for every study kind)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...errors import InputError, UnknownNameError
from .picture import Picture
from .source import open_run

__all__ = ["picture_of"]


def picture_of(source: Any, field: str | None = None, **options) -> Picture:
    """The picture of ``source`` (a result object or a run directory) drawn by its kind's view
    function (``options`` go to it), or the generic picture of its run directory; a study's
    output directory: its report's figure (``field``: which one)."""
    from ...kinds import KINDS
    from .study import is_study_dir, study_picture

    if hasattr(source, "figures") and getattr(source, "output_dir", None) is not None:
        source = source.output_dir  # a study's result: its report directory
    if isinstance(source, (str, Path)) and is_study_dir(Path(source)):
        if options:
            raise InputError(f"{source}: a study's figure takes no options (given: "
                             f"{', '.join(sorted(options))})")
        return study_picture(Path(source), field)
    run = open_run(source)
    try:
        view = KINDS.get(run.problem, "problem").view
    except UnknownNameError:
        view = None  # a kind not loaded here: its files are drawn as they are
    if view is not None:
        return view(run, field=field, **options)
    from .generic import generic_picture

    return generic_picture(run, field=field)
