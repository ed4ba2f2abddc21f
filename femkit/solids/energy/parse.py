"""Energy expressions as SymPy trees, parsed without evaluation.

A user's energy (``"mu*(s-1)**2"``, ``"lam/2*(J-1)**2"``) is read with :func:`ast.parse`
(``mode="eval"``: one expression), every node is checked against a whitelist and the checked
tree is rebuilt node by node as a SymPy expression. Nothing reaches Python's code evaluator
(SymPy's own string parser evaluates text, so it is not used), so an expression can only do
arithmetic on the stretch variables and the named constants.

Allowed: numbers (kept exact: ``0.25`` is the rational 1/4), the variables and constants named by
the caller, ``pi`` and ``E``; ``+ - * / **`` and unary minus; the functions of :data:`FUNCTIONS`;
``where(condition, a, b)`` with one comparison ``< <= > >=`` as the condition (a piecewise
energy, e.g. stiffer in tension than in compression).

>>> import sympy
>>> s = sympy.Symbol("s")
>>> parse_energy("mu*(s-1)**2 + 0.5", {"s": s, "mu": sympy.Symbol("mu")})
mu*(s - 1)**2 + 1/2
>>> parse_energy("s.__class__", {"s": s})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
femkit.errors.MaterialError: energy 's.__class__': attribute access is not allowed; ...
"""

from __future__ import annotations

import ast
from typing import Mapping

from ...errors import MaterialError

__all__ = ["parse_energy", "FUNCTIONS", "MAX_LENGTH"]

#: Longest accepted expression (characters).
MAX_LENGTH = 4000

#: Functions an energy may call: name -> number of arguments (SymPy function looked up lazily).
FUNCTIONS: dict[str, int] = {"sqrt": 1, "exp": 1, "log": 1, "sin": 1, "cos": 1, "tanh": 1,
                             "cosh": 1, "sinh": 1, "atan": 1, "abs": 1, "min": 2, "max": 2,
                             "where": 3}

_SYMPY_NAMES = {"sqrt": "sqrt", "exp": "exp", "log": "log", "sin": "sin", "cos": "cos",
                "tanh": "tanh", "cosh": "cosh", "sinh": "sinh", "atan": "atan", "abs": "Abs",
                "min": "Min", "max": "Max"}


def _fail(text: str, what: str, names: Mapping) -> MaterialError:
    return MaterialError(
        f"energy {text!r}: {what}; allowed: numbers, the names {', '.join(sorted(names))}, pi, E, "
        f"+ - * / ** and the functions {', '.join(sorted(FUNCTIONS))} "
        "(where(a < b, x, y) for a piecewise energy)")


def parse_energy(text, names: Mapping[str, object]):
    """The SymPy expression of ``text`` over the symbols ``names`` (name -> SymPy expression).

    Raises
    ------
    MaterialError
        Not a string, too long, a syntax error, an unknown name (the valid ones listed) or any
        construct outside the whitelist (named).
    """
    import sympy

    if isinstance(text, (int, float)) and not isinstance(text, bool):
        text = repr(text)
    if not isinstance(text, str) or not text.strip():
        raise MaterialError(f"energy must be a non-empty expression string, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise MaterialError(f"energy expression longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise MaterialError(f"energy {text!r}: syntax error: {exc.msg}") from None
    binops = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
              ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
              ast.Pow: lambda a, b: a ** b}
    compares = {ast.Lt: sympy.Lt, ast.LtE: sympy.Le, ast.Gt: sympy.Gt, ast.GtE: sympy.Ge}
    fixed = {"pi": sympy.pi, "E": sympy.E}

    def rec(n, condition: bool = False):
        if isinstance(n, ast.Expression):
            return rec(n.body)
        if isinstance(n, ast.Constant):
            if isinstance(n.value, bool) or not isinstance(n.value, (int, float)):
                raise _fail(text, f"constant {n.value!r} is not a number", names)
            return sympy.Rational(repr(n.value)) if isinstance(n.value, float) \
                else sympy.Integer(n.value)
        if isinstance(n, ast.Name):
            if n.id in names:
                return names[n.id]
            if n.id in fixed:
                return fixed[n.id]
            raise _fail(text, f"unknown name {n.id!r}", names)
        if isinstance(n, ast.BinOp) and type(n.op) in binops:
            return binops[type(n.op)](rec(n.left), rec(n.right))
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
            v = rec(n.operand)
            return -v if isinstance(n.op, ast.USub) else v
        if isinstance(n, ast.Compare):
            if not condition:
                raise _fail(text, "a comparison is allowed only as where()'s condition", names)
            if len(n.ops) != 1 or type(n.ops[0]) not in compares:
                raise _fail(text, "where()'s condition must be one comparison < <= > >=", names)
            return compares[type(n.ops[0])](rec(n.left), rec(n.comparators[0]))
        if isinstance(n, ast.Call):
            fname = n.func.id if isinstance(n.func, ast.Name) else None
            if fname not in FUNCTIONS:
                raise _fail(text, f"call of {ast.unparse(n.func)!r} is not allowed", names)
            if n.keywords or len(n.args) != FUNCTIONS[fname]:
                raise _fail(text, f"{fname}() takes {FUNCTIONS[fname]} positional arguments",
                            names)
            if fname == "where":
                cond = rec(n.args[0], condition=True)
                return sympy.Piecewise((rec(n.args[1]), cond), (rec(n.args[2]), True))
            return getattr(sympy, _SYMPY_NAMES[fname])(*[rec(a) for a in n.args])
        raise _fail(text, f"{type(n).__name__.lower()} {ast.unparse(n)!r} is not allowed"
                    if not isinstance(n, ast.Attribute) else "attribute access is not allowed",
                    names)

    return rec(tree)
