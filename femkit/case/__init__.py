"""Case files: schema validation, safe expressions, loading and running.

``load_case(path, **overrides) -> Case``; ``Case.run(output_dir=None, quiet=True, write=True)``.
Kinds of file (``problem: poisson``, ``problem: mass_spring``, and the study kinds) are
dispatched through the one registry :data:`femkit.case.kinds.KINDS`; a new kind is one module
calling :func:`femkit.case.kinds.register_kind`.
"""

from .load import Case, apply_overrides, case_from_dict, load_case
from .kinds import KINDS, Kind, register_kind

__all__ = ["Case", "load_case", "case_from_dict", "apply_overrides", "KINDS", "Kind",
           "register_kind", "compile_expression"]


def __getattr__(name):  # compile_expression pulls numpy: import it on first use only
    if name == "compile_expression":
        from .expressions import compile_expression

        return compile_expression
    raise AttributeError(name)
