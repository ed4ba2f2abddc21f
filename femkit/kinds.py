"""Kinds of YAML file femkit reads: the one registry :data:`KINDS`, a leaf below the application.

A case or scene file names its kind with ``problem: <name>`` (``poisson``, ``mass_spring``), a
study file with ``kind: <name>`` (``poisson_convergence``, ``stability``, ...). Both are a
:class:`Kind`: its JSON schema, its typed run spec, the load-time check, the cost plan, the run
and, for studies, the report and the summary ``femkit study`` prints. Each built-in kind
registers itself from its own module (``femkit/case/<folder>/kind.py``: ``poisson/``,
``scene/``, ``solid/``; ``femkit/study/<name>/kind.py``); the loaders, ``femkit solve``,
``femkit study``, the cost check and the report dispatch through :data:`KINDS` alone.

This module imports no case or study module (it sits below both, beside the other shared
leaves). The package that owns a family hands it the function that finds its built-in kinds
(:meth:`KindRegistry.add_finder`): :mod:`femkit.case` for ``problem``, :mod:`femkit.study` for
``kind``, each scanning its own folders. So the case layer never loads a study module, and a
family is complete once its package is imported (``femkit list`` and the schema import both).

Discovery is lazy: nothing is imported until a kind is first looked up, so ``femkit --help`` and
a bad-input exit stay fast. The first look-up of a family runs its finders, and the first
look-up of any kind loads the plugins (:mod:`femkit.plugins`): modules of the ``femkit.plugins``
entry-point group of installed packages, and the modules named in the ``FEMKIT_PLUGINS``
environment variable.

Adding a kind is one module::

    from femkit.kinds import Kind, register_kind

    register_kind(Kind("heatbar", "problem", schema=heatbar_schema, prepare=prepare, run=run))

>>> import femkit.case  # hands KINDS the finder of the problem kinds
>>> sorted(n for n in KINDS.names("problem"))[:2]
['heat', 'mass_spring']
>>> KINDS.get("heatbar", "problem")
Traceback (most recent call last):
...
femkit.errors.UnknownNameError: unknown problem 'heatbar'; valid problems: heat, mass_spring, poisson, solid, wave
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from .errors import UnknownNameError

__all__ = ["Kind", "KINDS", "KindRegistry", "register_kind", "FAMILIES"]

#: The top-level key naming the kind of a file -> what such a file is called in messages.
FAMILIES = {"problem": "problem", "kind": "study kind"}


@dataclass(frozen=True)
class Kind:
    """One kind of YAML file.

    Parameters
    ----------
    name : str
        The value of the file's naming key (``problem: poisson`` -> ``"poisson"``).
    key : str
        ``"problem"`` (a case or scene file, run by ``femkit solve``) or ``"kind"`` (a study
        file, run by ``femkit study``).
    schema : dict or callable
        The JSON schema of the file (cases: the whole file; studies: the kind's own top-level
        properties, the common study keys are added by :func:`femkit.study.schema.schema_for`),
        or a zero-argument function returning it (so names registered later, e.g. a plugin
        force, appear in its enums).
    prepare : callable
        ``prepare(case_or_study)``: the load-time checks beyond the schema (names against the
        registries, expressions, files), building the frozen run spec (``.spec``).
    run : callable
        Cases: ``run(case, output_dir=None, quiet=False, write=True, echo=None)`` returning a
        result with ``converged``. Studies: ``run(study, progress_enabled=None)`` returning
        ``{"records", "fits"?, "tables"?, "notes"?, ...}``.
    plan : callable, optional
        ``plan(case_or_study, measure=True) -> femkit.cost.Plan``: the cost before the run
        (``--dry-run``, budgets). Without it the run is unchecked (studies: a count of runs).
    report : callable, optional
        Studies: ``report(report, study, result, data, stage)`` fills the report.
    summary : callable, optional
        Studies: ``summary(result) -> list[str]``, the lines ``femkit study`` prints.
    default_solver : str, optional
        The solver method of the kind's linear solves when the file names none (``solver:`` /
        ``linear_solver:`` without ``method``): the one home of that default (``pcg`` for
        Poisson, ``direct`` for scenes, ``cholesky`` for the cloth study). None: the kind takes no
        solver mapping of its own.
    view : callable, optional
        Problems: ``view(source, field=None, **options) -> femkit.view.core.Picture``, the
        picture of a result object or a run directory (``source``) that ``femkit view`` and
        ``result.plot()`` draw; a kind's package declares it in its ``kind.py`` and imports its
        view module on first use. None: the generic picture of the run directory (its ``.pvd``
        time series, else its ``solution.vtu``; :mod:`femkit.view.core.generic`).
    """

    name: str
    key: str
    schema: Any
    prepare: Callable
    run: Callable
    plan: Callable | None = None
    report: Callable | None = None
    summary: Callable | None = None
    default_solver: str | None = None
    view: Callable | None = None

    def __post_init__(self):
        if self.key not in FAMILIES:
            raise ValueError(f"Kind.key must be one of {', '.join(FAMILIES)}, got {self.key!r}")

    def get_schema(self) -> dict:
        """The JSON schema (calling ``schema`` when it is a function)."""
        return self.schema() if callable(self.schema) else self.schema

    # the names the problem-type API used
    def get_prepare(self) -> Callable:
        return self.prepare

    def get_run(self) -> Callable:
        return self.run


class KindRegistry:
    """Every :class:`Kind`, by name; built-in kinds and plugins load on the first look-up."""

    def __init__(self):
        self._items: dict[str, Kind] = {}
        self._finders: dict[str, list[Callable[[], None]]] = {family: [] for family in FAMILIES}

    def add_finder(self, family: str, finder: Callable[[], None]) -> None:
        """Have ``finder()`` import the built-in kinds of ``family`` (``"problem"`` or
        ``"kind"``) at that family's next look-up; each finder runs once."""
        if family not in FAMILIES:
            raise ValueError(f"family must be one of {', '.join(FAMILIES)}, got {family!r}")
        self._finders[family].append(finder)

    def register(self, kind: Kind) -> Kind:
        if kind.name in self._items:
            raise ValueError(f"{FAMILIES[kind.key]} {kind.name!r} registered twice")
        self._items[kind.name] = kind
        return kind

    def remove(self, name: str) -> Kind:
        self._discover(None)
        kind = self._items.pop(name, None)
        if kind is None:
            raise UnknownNameError("kind", str(name), self._items)
        return kind

    def _discover(self, key: str | None) -> None:
        """Run the pending finders of family ``key`` (of every family for None), then load the
        plugins (a case look-up never imports the study kinds)."""
        for family in (FAMILIES if key is None else (key,)):
            pending = self._finders[family]
            while pending:
                pending.pop(0)()
        from .plugins import load_plugins

        load_plugins()

    def _of(self, key: str | None) -> dict[str, Kind]:
        self._discover(key)
        return {n: k for n, k in self._items.items() if key is None or k.key == key}

    def get(self, name: Any, key: str | None = None) -> Kind:
        """The kind called ``name`` (of family ``key`` when given); UnknownNameError lists the
        valid names of that family."""
        items = self._of(key)
        try:
            return items[name]
        except (KeyError, TypeError):
            raise UnknownNameError(FAMILIES.get(key, "kind"), str(name), items) from None

    def names(self, key: str | None = None) -> list[str]:
        return sorted(self._of(key))

    def __contains__(self, name: object) -> bool:
        return name in self._of(None)

    def __iter__(self):
        return iter(self.names())

    def __len__(self) -> int:
        return len(self._of(None))


#: name -> Kind, for every kind of file (``problem:`` and ``kind:``)
KINDS = KindRegistry()


def register_kind(kind: Kind) -> Kind:
    """Register ``kind`` (ValueError when its name is taken); returns it."""
    return KINDS.register(kind)
