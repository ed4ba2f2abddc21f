"""What a picture is made from: :class:`Run` (a result object, its run directory, its facts);
:func:`check_field`, the one check of a field name.

The dispatch to the kind's view function is :func:`femkit.view.core.dispatch.picture_of`. A
kind declares its view in its own package (:attr:`femkit.kinds.Kind.view`, imported on first
use, like its ``run``); a kind without one gets the generic picture of its run directory
(:func:`femkit.view.core.generic.generic_picture`: the ``.pvd`` time series, else
``solution.vtu``), so a time-dependent kind that writes a PVD is drawn without any code of its
own. This module imports no case module (the problem kinds are registered by whoever imported
them: :func:`femkit.view.open_view` imports :mod:`femkit.case` first).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...errors import InputError, UnknownNameError

__all__ = ["Run", "open_run", "check_field"]


@dataclass
class Run:
    """A run to draw.

    Parameters
    ----------
    problem : str
        Its kind (``result.json``'s ``problem``).
    name : str
        The case's name (for titles).
    result : RunResult, optional
        The result object, when drawing one in memory (``result.plot()``).
    directory : Path, optional
        Its run directory (None for a run that wrote nothing).
    facts : dict
        ``result.json`` (or ``result.to_dict()``).
    """

    problem: str
    name: str
    result: Any = None
    directory: Path | None = None
    facts: dict = field(default_factory=dict)

    def file(self, name: str) -> Path:
        """The run directory's file ``name``; an InputError when it is not there."""
        if self.directory is None:
            raise InputError(f"{self.name}: the run wrote no files, and this picture is drawn from "
                             f"its {name}: run it with an output directory")
        path = self.directory / name
        if not path.exists():
            raise InputError(f"{self.directory}: no {name} (the case's output did not ask for it?)")
        return path


def open_run(source: Any) -> Run:
    """A :class:`Run` of a result object (``RunResult``) or of a run directory (a path).

    Raises
    ------
    InputError
        ``source`` is not a directory holding a ``result.json``.
    """
    if hasattr(source, "case") and hasattr(source, "to_dict"):
        directory = getattr(source, "output_dir", None)
        return Run(problem=source.case.problem, name=source.case.name, result=source,
                   directory=Path(directory) if directory is not None else None, facts={})
    path = Path(source)
    meta = path / "result.json"
    if not path.is_dir() or not meta.is_file():
        raise InputError(f"{path}: neither a femkit run directory (result.json, from 'femkit "
                         "solve') nor a study's output (report.md and results.json, from "
                         "'femkit study')")
    try:
        facts = json.loads(meta.read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{meta}: unreadable ({exc})") from None
    return Run(problem=str(facts.get("problem")), name=str(facts.get("case", path.name)),
               directory=path, facts=facts)


def check_field(field: str | None, fields: list[str] | tuple[str, ...], default: str) -> str:
    """``field`` (``default`` when None) if the source has it, else an UnknownNameError listing
    ``fields``."""
    name = default if field is None else field
    if name not in fields:
        raise UnknownNameError("field", str(name), fields)
    return name
