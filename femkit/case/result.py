"""The one base type of what a run of a case file produced: :class:`RunResult`.

Every problem kind's result extends it (Poisson :class:`femkit.case.poisson.problem.CaseResult`,
scenes :class:`femkit.case.scene.run.SceneResult`, solids :class:`femkit.case.solid.run.SolidResult`,
and a kind added by a plugin), so ``femkit solve``, the studies and the tests read every result the
same way: ``converged``, ``interrupted``, ``verdict``, ``timings``, ``files``, ``output_dir``,
``summary_lines()``, ``to_dict()`` (``result.json``) and :meth:`RunResult.write_result_json`;
:meth:`RunResult.plot` draws any of them (pyvista: the extra ``femkit[view]``).

A kind writes only its own facts (:meth:`RunResult.facts`); the keys every ``result.json`` starts
with (``case``, ``problem``, ``case_file``, ``femkit_version``) are written here.

>>> from dataclasses import dataclass, field
>>> from types import SimpleNamespace
>>> @dataclass
... class Demo(RunResult):
...     case: object
...     timings: dict = field(default_factory=dict)
...     files: list = field(default_factory=list)
...     output_dir: object = None
...     converged: bool = True
...     def facts(self):
...         return {"answer": 42}
...     def summary_lines(self):
...         return [f"demo      {self.case.name}", self.timings_line()]
>>> r = Demo(SimpleNamespace(name="d", problem="demo", path=None), {"solve": 0.5})
>>> [k for k in r.to_dict()], r.verdict, r.summary_lines()[1]
(['case', 'problem', 'case_file', 'femkit_version', 'answer'], 'converged', 'time      solve 0.500 s')
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Iterable

__all__ = ["RunResult"]


class RunResult:
    """Base of every problem kind's result (a kind's result is a dataclass extending it).

    A subclass provides ``case`` (the :class:`femkit.case.load.Case` run), ``timings`` (stage ->
    seconds), ``files`` (names written, ``result.json`` included), ``output_dir`` (None when
    nothing was written) and ``converged``, and implements :meth:`facts` and
    :meth:`summary_lines`. ``interrupted`` (the signal that stopped the run, else None) and
    ``verdict`` have defaults a kind may override.
    """

    case: Any
    timings: dict
    files: list
    output_dir: Any

    @property
    def converged(self) -> bool:
        """Whether the run reached its end as asked (``femkit solve`` exits 1 when not)."""
        raise NotImplementedError(f"{type(self).__name__} must say whether it converged")

    @property
    def interrupted(self) -> str | None:
        """The signal (``"SIGINT"`` ...) or stop request that ended the run early, else None."""
        return None

    @property
    def verdict(self) -> str:
        """One word: ``converged``, ``interrupted`` or ``failed`` (kinds name their failures:
        ``unstable``, ``newton_failed`` ...)."""
        if self.converged:
            return "converged"
        return "interrupted" if self.interrupted is not None else "failed"

    def header(self) -> dict:
        """The keys every ``result.json`` starts with: the file run and femkit's version."""
        from .._version import __version__

        case = self.case
        return {"case": case.name, "problem": case.problem,
                "case_file": str(case.path) if case.path else None,
                "femkit_version": __version__}

    def facts(self) -> dict:
        """The kind's own keys of ``result.json`` (after :meth:`header`)."""
        raise NotImplementedError(f"{type(self).__name__} must list its result.json facts")

    def to_dict(self) -> dict:
        """The content of ``result.json``: :meth:`header`, then :meth:`facts`."""
        return {**self.header(), **self.facts()}

    def summary_lines(self) -> list[str]:
        """The short human summary ``femkit solve`` prints."""
        raise NotImplementedError(f"{type(self).__name__} must summarise itself")

    def timings_line(self) -> str:
        """The summary's ``time`` line: every stage and its seconds."""
        return "time      " + ", ".join(f"{k} {v:.3f} s" for k, v in self.timings.items())

    def output_line(self, *, names: bool = False) -> str | None:
        """The summary's ``output`` line (the directory and the count of files, or their names
        with ``names``); None when nothing was written."""
        if self.output_dir is None:
            return None
        listed = ", ".join(self.files) if names else f"{len(self.files)} files"
        return f"output    {self.output_dir} ({listed})"

    def plot(self, field: str | None = None, **options):
        """The picture of this result, drawn by its kind's view function (``femkit[view]``:
        pyvista, imported only now); a notebook shows it inline.

        Parameters
        ----------
        field : str, optional
            The field to colour by (the kind's default when None); an unknown one raises
            :class:`~femkit.errors.UnknownNameError` listing the valid ones.
        **options
            ``size=(w, h)`` and the kind's own options (docs/views.md).

        Returns
        -------
        femkit.view.core.view.View
            ``.screenshot(path)``, ``.movie(path)``, ``.show()``, ``.frame(k)``.
        """
        from ..view.core import view_of

        return view_of(self, field=field, **options)

    def write_result_json(self, directory: str | os.PathLike, files: Iterable[str]) -> Path:
        """Record ``files`` (the names written, ``result.json`` among them) and write
        ``result.json`` into ``directory`` (:func:`femkit.io.writers.write_json`: atomic,
        strict JSON); returns its path."""
        from ..io.writers import write_json

        self.files = list(files)
        path = Path(directory) / "result.json"
        write_json(path, self.to_dict())
        return path
