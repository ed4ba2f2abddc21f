"""What every study kind's typed run spec shares (``study.spec``, built once by the loader).

Each study kind's ``prepare`` (its load-time check, ``femkit/study/<kind>/spec.py``) ends by
building its frozen record, a :class:`StudySpec` subclass, from the validated file whose
defaults the kind's schema filled: the sweep, the cost plan and the report read the record,
never ``study.data`` by string keys. Defaults the schema cannot state (the reference
step of a work-precision study: the smallest swept ``dt`` / 16) are computed here, once.
Every spec shares :class:`StudySpec`'s keys (``title``, ``description``, ``output``,
``repeats``, ``warmup``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

__all__ = ["StudySpec", "plain", "load_base_case"]


@dataclass(frozen=True)
class StudySpec:
    """The keys every study kind has (defaults: :data:`femkit.study.schema.COMMON`)."""

    title: str | None
    description: str | None
    output: str | None
    repeats: int
    warmup: int

    @classmethod
    def common(cls, d: Mapping) -> dict:
        return dict(title=d.get("title"), description=d.get("description"),
                    output=d.get("output"), repeats=int(d["repeats"]), warmup=int(d["warmup"]))


def plain(value: Any) -> Any:
    """A read-only copy of a mapping or list of the file (:func:`femkit.case.frozen.freeze`:
    ``dict``/``list`` subclasses, so schemas and writers still accept them)."""
    from ..case.frozen import freeze

    return freeze(value)


def load_base_case(study, **overrides):
    """``(path, case)`` of the study's ``base_case`` (relative to the study file), with the
    spec's ``case_overrides`` and then ``overrides`` merged.

    Raises
    ------
    CaseFileError
        The file does not exist.
    """
    from ..case import load_case
    from ..errors import CaseFileError

    d = study.spec
    path = study.resolve(d.base_case)
    if not path.is_file():
        raise CaseFileError(f"base_case: file not found: {path}")
    return path, load_case(path, **{**dict(d.case_overrides), **overrides})
