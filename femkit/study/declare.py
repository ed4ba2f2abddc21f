"""A study kind declared by its package: the one registration a kind's ``kind.py`` makes.

A study kind is one package (built in: ``femkit/study/<name>/``; a plugin: any importable
package, :mod:`femkit.plugins`) whose modules hold everything about it, under fixed names:

============  =====================================================================  ========
module        defines                                                                needed
============  =====================================================================  ========
``__init__``  the docstring: its first sentence is what ``femkit list`` says          yes
``schema``    ``schema() -> dict``: the JSON-schema properties of the kind's own      yes
              top-level keys (:func:`femkit.study.schema.schema_for` adds the
              common ones and the ``quick:`` block)
``spec``      ``prepare(study)``: the load-time checks beyond the schema; sets        yes
              ``study.spec`` (a frozen :class:`femkit.study.spec.StudySpec`)
``run``       ``run(study, progress_enabled=None) -> dict``: the sweep,               yes
              ``{"records", "fits"?, "tables"?, "notes"?, ...}``
``report``    ``build(report, study, result, data, stage)`` fills the report;         yes
              ``summary(result) -> list[str]`` the lines ``femkit study`` prints
              (optional)
``cost``      ``plan(study) -> femkit.cost.Plan``: the cost before the run            no
              (``--dry-run``, budgets); without it the plan says there is no model
``kind``      ``KIND = study_kind("<name>", __package__)``                            yes
============  =====================================================================  ========

:func:`study_kind` builds the :class:`~femkit.kinds.Kind` from those names and registers it.
Each callable imports its module at its first call, so finding the kinds (``femkit list``, a
study file's first look-up, a bad-input exit) imports only the ``kind`` modules.
The test that a kind is one package: ``tests/study/test_plugin_kind.py``.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import Callable

from ..kinds import Kind, register_kind

__all__ = ["study_kind", "NEEDED"]

#: The modules every study kind's package has (``cost`` is optional).
NEEDED = ("schema", "spec", "run", "report")


def _deferred(package: str, module: str, attr: str) -> Callable:
    """``package.module.attr``, imported at its first call (named after the package, whose
    docstring says what the kind is: :func:`femkit.catalog.describe` reads it)."""

    def call(*args, **kwargs):
        return getattr(importlib.import_module(f"{package}.{module}"), attr)(*args, **kwargs)

    call.__module__ = package
    call.__name__ = call.__qualname__ = f"{module}.{attr}"
    return call


def _summary(package: str) -> Callable:
    """The report module's ``summary`` (no lines when it defines none)."""

    def summary(result) -> list[str]:
        fn = getattr(importlib.import_module(f"{package}.report"), "summary", None)
        return list(fn(result)) if fn is not None else []

    summary.__module__ = package
    return summary


def study_kind(name: str, package: str, *, default_solver: str | None = None) -> Kind:
    """Register the study kind ``name`` whose modules are the package ``package`` (a kind's
    ``kind.py`` passes its ``__package__``); returns the :class:`~femkit.kinds.Kind`.

    Parameters
    ----------
    name : str
        The ``kind:`` value of its study files.
    package : str
        The dotted name of the kind's package (modules ``schema``, ``spec``, ``run``,
        ``report`` and optionally ``cost``, see the module docstring).
    default_solver : str, optional
        The solver method of its linear solves when the file names none
        (:attr:`femkit.kinds.Kind.default_solver`).

    Raises
    ------
    ValueError
        ``name`` is registered already, or the package lacks one of the needed modules (a
        plugin's is then a one-line :class:`~femkit.errors.InputError`, :mod:`femkit.plugins`).
    """
    missing = [m for m in NEEDED if importlib.util.find_spec(f"{package}.{m}") is None]
    if missing:
        raise ValueError(f"study kind {name!r}: package {package} has no {missing[0]}.py (a study "
                         f"kind's package holds {', '.join(NEEDED)} and optionally cost)")
    has_cost = importlib.util.find_spec(f"{package}.cost") is not None
    return register_kind(Kind(
        name, "kind", schema=_deferred(package, "schema", "schema"),
        prepare=_deferred(package, "spec", "prepare"), run=_deferred(package, "run", "run"),
        plan=_deferred(package, "cost", "plan") if has_cost else None,
        report=_deferred(package, "report", "build"), summary=_summary(package),
        default_solver=default_solver))
