"""Case files: schema validation, safe expressions, loading and running.

``load_case(path, **overrides) -> Case``; ``Case.run(output_dir=None, quiet=True, write=True)``.
Kinds of file (``problem: poisson``, ``problem: mass_spring``, ``problem: solid``) are
dispatched through the one registry :data:`femkit.kinds.KINDS` (a leaf below this package). Each
kind is one package owning everything about it (``kind.py`` registering it with
:func:`femkit.kinds.register_kind`, its schema, spec, plan, run and a result extending
:class:`femkit.case.result.RunResult`); this package's own modules hold what kinds share
(loading, expressions, specs and schema fragments, ``cost.py``, ``result.py``, ``timeline.py``,
``pictures.py``). It hands the registry the finder of its built-in kinds: the ``kind.py`` of
each of its folders.
"""

import importlib
import importlib.util
import pkgutil

from ..kinds import KINDS, Kind, register_kind
from .load import Case, apply_overrides, case_from_dict, load_case


def _find_problem_kinds() -> None:
    """Import ``femkit/case/<folder>/kind.py`` of every folder here: each registers its kind."""
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.ispkg and importlib.util.find_spec(f"{__name__}.{info.name}.kind"):
            importlib.import_module(f"{__name__}.{info.name}.kind")


KINDS.add_finder("problem", _find_problem_kinds)

__all__ = ["Case", "load_case", "case_from_dict", "apply_overrides", "KINDS", "Kind",
           "register_kind", "compile_expression"]


def __getattr__(name):  # compile_expression pulls numpy: import it on first use only
    if name == "compile_expression":
        from .expressions import compile_expression

        return compile_expression
    raise AttributeError(name)
