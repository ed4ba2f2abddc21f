"""Problem types a case file can declare with ``problem: <name>``.

:data:`PROBLEMS` maps a problem name to a :class:`ProblemType`: where its JSON schema lives, the
function that checks and compiles a validated case (names against registries, expressions,
paths) and the function that runs it. Entries are ``"module:attribute"`` strings resolved on
first use, so listing a problem type imports nothing heavy.

Adding a problem type is one entry (as for the dynamics ``mass_spring`` scenes)::

    PROBLEMS["my_problem"] = ProblemType(
        schema="my.module:SCHEMA",        # JSON schema dict (additionalProperties: false)
        prepare="my.module:prepare",      # (case: Case) -> None: names, paths, expressions
        run="my.module:run",              # (case, output_dir=None, quiet=False, write=True,
    )                                     #  echo=None) -> result with .converged

or, from outside this package, :func:`register_problem`. ``femkit solve`` dispatches on the
``problem`` key through this table; a result whose ``converged`` attribute is false makes the
command exit with code 1.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from ..errors import UnknownNameError


def resolve(ref: Any) -> Any:
    """Import ``"package.module:attr"`` and return the attribute (non-strings pass through)."""
    if not isinstance(ref, str):
        return ref
    module, _, attr = ref.partition(":")
    obj = importlib.import_module(module)
    for part in attr.split("."):
        obj = getattr(obj, part)
    return obj


@dataclass(frozen=True)
class ProblemType:
    """How to validate, prepare and run one ``problem:`` kind (references may be lazy strings)."""

    schema: Any
    prepare: Any
    run: Any

    def get_schema(self) -> dict:
        return resolve(self.schema)

    def get_prepare(self):
        return resolve(self.prepare)

    def get_run(self):
        return resolve(self.run)


#: problem name -> ProblemType
PROBLEMS: dict[str, ProblemType] = {
    "poisson": ProblemType(
        schema="femkit.case.schema_poisson:POISSON_SCHEMA",
        prepare="femkit.case.run:prepare_poisson",
        run="femkit.case.run:run_poisson",
    ),
    "mass_spring": ProblemType(
        schema="femkit.dynamics.scene_schema:SCENE_SCHEMA",
        prepare="femkit.dynamics.scene:prepare_scene",
        run="femkit.dynamics.scene:run_scene",
    ),
}


def register_problem(name: str, schema: Any, prepare: Any, run: Any) -> None:
    """Register a problem type (objects or lazy ``"module:attr"`` strings)."""
    if name in PROBLEMS:
        raise ValueError(f"problem type {name!r} registered twice")
    PROBLEMS[name] = ProblemType(schema, prepare, run)


def get_problem(name: Any) -> ProblemType:
    """The :class:`ProblemType` called ``name``; UnknownNameError lists the valid ones."""
    try:
        return PROBLEMS[name]
    except (KeyError, TypeError):
        raise UnknownNameError("problem", str(name), PROBLEMS) from None
