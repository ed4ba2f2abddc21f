"""Problem types a case file can declare with ``problem: <name>``: the registry :data:`PROBLEMS`.

Each entry is a :class:`ProblemType`: a function returning its JSON schema, the function that
checks and compiles a validated case (names against registries, expressions, paths) and the
function that runs it. The built-in entries import their modules on first use (plain
functions below, no import strings), so listing problem types imports nothing heavy.

Adding a problem type is one registration::

    register_problem("my_problem", schema=MY_SCHEMA, prepare=prepare, run=run, plan=plan)

``run(case, output_dir=None, quiet=False, write=True, echo=None)`` returns a result with
``converged``; ``femkit solve`` dispatches on the ``problem`` key through this registry and
exits with code 1 when ``converged`` is false.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from ..registry import Registry

__all__ = ["PROBLEMS", "ProblemType", "register_problem", "get_problem"]


@dataclass(frozen=True)
class ProblemType:
    """How to validate, prepare and run one ``problem:`` kind.

    ``schema`` is the JSON-schema dict or a zero-argument function returning it.
    """

    schema: Any
    prepare: Callable
    run: Callable
    plan: Callable | None = None

    def get_schema(self) -> dict:
        return self.schema() if callable(self.schema) else self.schema

    def get_prepare(self) -> Callable:
        return self.prepare

    def get_run(self) -> Callable:
        return self.run


#: problem name -> ProblemType
PROBLEMS: Registry = Registry("problem")


def register_problem(name: str, schema: Any, prepare: Callable, run: Callable,
                     plan: Callable | None = None) -> ProblemType:
    """Register a problem type; a name registered twice raises ValueError.

    ``plan(case, measure=True) -> femkit.cost.Plan`` predicts a run's cost (``--dry-run``,
    budgets); without it such cases are run unchecked.
    """
    return PROBLEMS.register(name, ProblemType(schema, prepare, run, plan))


def get_problem(name: Any) -> ProblemType:
    """The :class:`ProblemType` called ``name``; UnknownNameError lists the valid ones."""
    return PROBLEMS.get(name)


# ----------------------------------------------------------------------------- built-in types

def _poisson_schema() -> dict:
    from .poisson.schema import POISSON_SCHEMA

    return POISSON_SCHEMA


def _poisson_prepare(case) -> None:
    from .poisson.run import prepare_poisson

    prepare_poisson(case)


def _poisson_run(case, **kwargs):
    from .poisson.run import run_poisson

    return run_poisson(case, **kwargs)


def _scene_schema() -> dict:
    from .scene.schema import SCENE_SCHEMA

    return SCENE_SCHEMA


def _scene_prepare(case) -> None:
    from .scene.run import prepare_scene

    prepare_scene(case)


def _scene_run(case, **kwargs):
    from .scene.run import run_scene

    return run_scene(case, **kwargs)


def _poisson_plan(case, **kwargs):
    from .cost import plan_poisson_case

    return plan_poisson_case(case, **kwargs)


def _scene_plan(case, **kwargs):
    from .cost import plan_scene_case
    from .scene.run import build_context, build_integrator, build_system

    return plan_scene_case(case, build_system(case)[0], build_integrator(case),
                           ctx=build_context(case), **kwargs)


register_problem("poisson", _poisson_schema, _poisson_prepare, _poisson_run, _poisson_plan)
register_problem("mass_spring", _scene_schema, _scene_prepare, _scene_run, _scene_plan)
