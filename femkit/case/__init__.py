"""Case files: schema validation, safe expressions, loading and running.

``load_case(path, **overrides) -> Case``; ``Case.run(output_dir=None, quiet=True, write=True)``.
Problem types (``poisson``, later ``mass_spring``) are dispatched through
:data:`femkit.case.problems.PROBLEMS`.
"""

from .load import Case, apply_overrides, case_from_dict, load_case
from .problems import PROBLEMS, ProblemType, register_problem

__all__ = ["Case", "load_case", "case_from_dict", "apply_overrides", "PROBLEMS", "ProblemType",
           "register_problem", "compile_expression"]


def __getattr__(name):  # compile_expression pulls numpy: import it on first use only
    if name == "compile_expression":
        from .expressions import compile_expression

        return compile_expression
    raise AttributeError(name)
