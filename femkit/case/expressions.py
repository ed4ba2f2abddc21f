"""Safe arithmetic expressions of ``x``, ``y`` (and ``z`` on tetrahedra) for case files.

An expression string such as ``"2*pi**2*sin(pi*x)*sin(pi*y)"`` is parsed with
:func:`ast.parse` (``mode="eval"``, an expression only), every node of the tree is checked against a
whitelist, and the checked tree is turned into a chain of small numpy closures. Nothing
is ever handed to Python's code evaluator, so an expression can only do arithmetic.

Allowed:

- numbers (``1``, ``2.5``, ``1e-3``), the variables (``x``, ``y`` by default),
  the constants ``pi`` and ``e`` and any user constants passed in;
- ``+ - * / **`` and unary ``-``/``+``; comparisons ``< <= > >= == !=`` (they give 0/1);
- calls of the functions in :data:`FUNCTIONS` (numpy ufuncs, ``where(cond, a, b)``)
  with positional arguments.

Everything else (attribute access, subscripts, other calls, lambdas, strings,
comprehensions, ...) raises :class:`~femkit.errors.ExpressionError` naming the
offending piece and listing what is allowed.

>>> import numpy as np
>>> f = compile_expression("2*pi**2*sin(pi*x)*sin(pi*y)")
>>> round(float(f(np.array([0.5]), np.array([0.5]))[0]), 6)
19.739209
>>> compile_expression("3")(np.zeros(2), np.zeros(2))
array([3., 3.])
>>> g = compile_expression("x + y", ("x", "y", "z"))  # z unused: callable with (x, y) too
>>> float(g(1.0, 2.0)), float(g(1.0, 2.0, 5.0)), sorted(g.used)
(3.0, 3.0, ['x', 'y'])
>>> compile_expression("x.__class__")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
femkit.errors.ExpressionError: expression 'x.__class__': attribute access is not allowed; ...
"""

from __future__ import annotations

import ast
import difflib
import math
import operator
from typing import Callable, Mapping, Sequence

import numpy as np

from ..errors import ExpressionError

__all__ = ["compile_expression", "compile_case_expression", "Expression", "Gradient", "FUNCTIONS",
           "CONSTANTS", "MAX_LENGTH"]

#: Functions an expression may call: name -> (numpy function, number of arguments).
FUNCTIONS: dict[str, tuple[Callable, int]] = {
    "sin": (np.sin, 1), "cos": (np.cos, 1), "tan": (np.tan, 1),
    "arcsin": (np.arcsin, 1), "arccos": (np.arccos, 1), "arctan": (np.arctan, 1),
    "asin": (np.arcsin, 1), "acos": (np.arccos, 1), "atan": (np.arctan, 1),
    "sinh": (np.sinh, 1), "cosh": (np.cosh, 1), "tanh": (np.tanh, 1),
    "exp": (np.exp, 1), "log": (np.log, 1), "log10": (np.log10, 1), "sqrt": (np.sqrt, 1),
    "abs": (np.abs, 1), "sign": (np.sign, 1), "floor": (np.floor, 1), "ceil": (np.ceil, 1),
    "arctan2": (np.arctan2, 2), "atan2": (np.arctan2, 2), "hypot": (np.hypot, 2),
    "minimum": (np.minimum, 2), "maximum": (np.maximum, 2), "min": (np.minimum, 2),
    "max": (np.maximum, 2), "mod": (np.mod, 2),
    "where": (np.where, 3),
}

#: Named constants every expression knows.
CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e}

#: Longest accepted expression (characters); guards against pathological input.
MAX_LENGTH = 4000

_BINOPS = {ast.Add: (np.add, "+"), ast.Sub: (np.subtract, "-"), ast.Mult: (np.multiply, "*"),
           ast.Div: (np.true_divide, "/"), ast.Pow: (np.power, "**")}
_UNARY = {ast.USub: np.negative, ast.UAdd: np.positive}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
            ast.GtE: operator.ge, ast.Eq: operator.eq, ast.NotEq: operator.ne}

_DESCRIBE = {
    ast.Attribute: "attribute access", ast.Subscript: "subscript", ast.Lambda: "lambda",
    ast.ListComp: "comprehension", ast.GeneratorExp: "generator", ast.SetComp: "comprehension",
    ast.DictComp: "comprehension", ast.List: "list", ast.Tuple: "tuple", ast.Dict: "dict",
    ast.Set: "set", ast.JoinedStr: "f-string", ast.IfExp: "conditional expression (use where())",
    ast.BoolOp: "and/or (use where() and comparisons)", ast.NamedExpr: "assignment",
    ast.Starred: "starred argument", ast.Await: "await", ast.Yield: "yield",
    ast.Slice: "slice",
}


def _allowed_text(variables: Sequence[str], constants: Mapping[str, float]) -> str:
    names = ", ".join([*variables, *CONSTANTS, *sorted(constants)])
    return (f"allowed: numbers, names {names}, operators + - * / ** and comparisons, "
            f"functions {', '.join(sorted(FUNCTIONS))}")


class Expression:
    """A checked, compiled expression; call it with numpy arrays.

    Parameters are the arrays of the variables, positionally, in the order of
    ``variables``. The result is a float64 array of the broadcast shape of the
    arguments (scalars are broadcast).

    Attributes
    ----------
    source : str
        The expression text, as given (numbers are turned into text).
    variables : tuple of str
        Names of the positional arguments.
    is_constant : bool
        True when the expression uses no variable.
    used : frozenset of str
        The variables the expression uses.
    label : str
        Where the expression comes from (a case-file key path); prefixes error messages.
    """

    def __init__(self, source: str, variables: tuple[str, ...], fn: Callable,
                 is_constant: bool, check_finite: bool, used: frozenset = frozenset(),
                 tree: ast.expr | None = None, names: Mapping[str, float] | None = None):
        self.source = source
        self.variables = variables
        self._fn = fn
        self.is_constant = is_constant
        self.used = frozenset(used)
        self.check_finite = check_finite
        self.label = ""  # where the expression comes from (e.g. "source"), used in messages
        #: The checked tree the closures were built from (a number: one ``ast.Constant``) and
        #: the values of the named constants it may use: what the compiled form is generated from.
        self.tree = tree
        self.names = dict(names or {})
        #: Compiled kernels evaluating this expression with others (:mod:`femkit.fem.fused`),
        #: set by :mod:`femkit.case.compiled_expressions`; None: NumPy only.
        self.fused = None

    def __call__(self, *args):
        # Trailing variables the expression does not use may be left out: an expression of
        # (x, y, z) that never names z is also a function of (x, y) (a 2D mesh).
        n = len(args)
        if n > len(self.variables) or self.used & set(self.variables[n:]):
            raise TypeError(f"expression {self.source!r} takes {len(self.variables)} arguments "
                            f"({', '.join(self.variables)}), got {len(args)}")
        arrays = [np.asarray(a, dtype=np.float64) for a in args]
        shape = np.broadcast_shapes(*(a.shape for a in arrays)) if arrays else ()
        with np.errstate(all="ignore"):
            value = self._fn(dict(zip(self.variables, arrays)))
        out = np.array(np.broadcast_to(np.asarray(value, dtype=np.float64), shape))
        if self.check_finite and not np.all(np.isfinite(out)):
            bad = np.flatnonzero(~np.isfinite(out.ravel()))
            where = ""
            if arrays and bad.size:
                k = int(bad[0])
                coords = ", ".join(f"{n}={float(np.broadcast_to(a, shape).ravel()[k]):.6g}"
                                   for n, a in zip(self.variables, arrays))
                where = f", first at ({coords})"
            label = f"{self.label}: " if self.label else ""
            raise ExpressionError(f"{label}expression {self.source!r} gave non-finite values at "
                                  f"{bad.size} of {out.size} points{where}")
        return out

    def __repr__(self) -> str:
        return f"Expression({self.source!r}, variables={self.variables})"


class Gradient:
    """The components of a gradient, each an :class:`Expression`, as one callable
    ``(x, y[, z]) -> (d/dx, d/dy[, d/dz])``.

    ``fused`` is the compiled kernels the components share (:mod:`femkit.fem.fused`), or None.
    """

    def __init__(self, parts: Sequence[Expression]):
        self.parts = tuple(parts)

    def __call__(self, *xyz):
        return tuple(g(*xyz) for g in self.parts)

    @property
    def fused(self):
        kernels = self.parts[0].fused if self.parts else None
        same = kernels is not None and len(kernels.gradient) == len(self.parts) and all(
            a is b for a, b in zip(kernels.gradient, self.parts))
        return kernels if same else None

    def __repr__(self) -> str:
        return f"Gradient({', '.join(repr(g.source) for g in self.parts)})"


def _fail(text: str, node: ast.AST | None, what: str, variables, constants) -> ExpressionError:
    piece = ast.get_source_segment(text, node) if node is not None else None
    where = f" (in {piece!r})" if piece and piece != text else ""
    return ExpressionError(f"expression {text!r}: {what}{where} is not allowed; "
                           f"{_allowed_text(variables, constants)}")


def compile_expression(text, variables: Sequence[str] = ("x", "y"),
                       constants: Mapping[str, float] | None = None, *,
                       check_finite: bool = True) -> Expression:
    """Parse ``text`` into a safe callable of ``variables``.

    Parameters
    ----------
    text : str or int or float
        The expression, e.g. ``"sin(pi*x)*sin(pi*y)"``; a plain number is accepted too.
    variables : sequence of str
        Names of the positional arguments of the returned callable.
    constants : mapping, optional
        Extra named numbers (e.g. ``{"k": 2.0}``) usable in the expression.
    check_finite : bool
        When true (default), a call producing NaN or inf raises ExpressionError.

    Returns
    -------
    Expression
        Callable ``f(*arrays) -> ndarray`` with ``.source`` holding the text.

    Raises
    ------
    ExpressionError
        Malformed expression, or any construct outside the whitelist.
    """
    variables = tuple(variables)
    constants = dict(constants or {})
    for name, value in constants.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ExpressionError(f"constant {name!r} must be a number, got {value!r}")
        if name in variables or name in FUNCTIONS:
            raise ExpressionError(f"constant {name!r} clashes with a variable or function name")
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise ExpressionError(f"expression must be a string or a number, got {text!r}")
    if not isinstance(text, str):
        value = float(text)
        if not math.isfinite(value):
            raise ExpressionError(f"expression value {text!r} is not finite")
        return Expression(repr(text), variables, lambda env, v=value: v, True, check_finite,
                          tree=ast.Constant(value))
    source = text.strip()
    if not source:
        raise ExpressionError("expression is empty")
    if len(source) > MAX_LENGTH:
        raise ExpressionError(f"expression is longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ExpressionError(f"cannot parse expression {source!r}: {exc.msg}{col}") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise ExpressionError(f"cannot parse expression {source!r}: {exc}") from None
    used: set[str] = set()
    names = {**CONSTANTS, **constants}
    try:
        fn = _build(tree.body, source, variables, names, constants, used)
    except RecursionError:
        raise ExpressionError(f"expression {source!r} is nested too deeply") from None
    expr = Expression(source, variables, fn, not (used & set(variables)), check_finite,
                      frozenset(used & set(variables)), tree=tree.body, names=names)
    if expr.is_constant and check_finite:
        expr(*([0.0] * len(variables)))  # a constant that is NaN/inf fails at load time
    return expr


def _build(node, text, variables, names, constants, used) -> Callable[[dict], object]:
    """Check ``node`` and return a closure ``env -> value`` computing it."""

    def rec(n):
        return _build(n, text, variables, names, constants, used)

    if isinstance(node, ast.Constant):
        v = node.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            kind = "string" if isinstance(v, (str, bytes)) else type(v).__name__
            raise _fail(text, node, f"{kind} constant", variables, constants)
        value = float(v)  # floats only: 10**10**10 overflows to inf instead of hanging
        return lambda env: value
    if isinstance(node, ast.Name):
        name = node.id
        if name in variables:
            used.add(name)
            return lambda env: env[name]
        if name in names:
            value = float(names[name])
            return lambda env: value
        valid = [*variables, *names]
        close = difflib.get_close_matches(name, valid + list(FUNCTIONS), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        what = (f"function {name!r} used as a value" if name in FUNCTIONS
                else f"unknown name {name!r}")
        raise ExpressionError(f"expression {text!r}: {what}{hint}; "
                              f"{_allowed_text(variables, constants)}")
    if isinstance(node, ast.BinOp):
        if type(node.op) not in _BINOPS:
            raise _fail(text, node, f"operator {type(node.op).__name__}", variables, constants)
        op = _BINOPS[type(node.op)][0]
        left, right = rec(node.left), rec(node.right)
        return lambda env: op(left(env), right(env))
    if isinstance(node, ast.UnaryOp):
        if type(node.op) not in _UNARY:
            raise _fail(text, node, f"operator {type(node.op).__name__}", variables, constants)
        op, operand = _UNARY[type(node.op)], rec(node.operand)
        return lambda env: op(operand(env))
    if isinstance(node, ast.Compare):
        ops = []
        for o in node.ops:
            if type(o) not in _COMPARE:
                raise _fail(text, node, f"comparison {type(o).__name__}", variables, constants)
            ops.append(_COMPARE[type(o)])
        parts = [rec(node.left)] + [rec(c) for c in node.comparators]

        def compare(env):
            vals = [p(env) for p in parts]
            result = True
            for op, a, b in zip(ops, vals, vals[1:]):
                result = np.logical_and(result, op(a, b))
            return np.asarray(result, dtype=np.float64)

        return compare
    if isinstance(node, ast.Call):
        func = node.func
        if not isinstance(func, ast.Name) or func.id not in FUNCTIONS:
            fname = func.id if isinstance(func, ast.Name) else None
            if fname is not None:
                close = difflib.get_close_matches(fname, list(FUNCTIONS), n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise _fail(text, node, f"call of unknown function {fname!r}{hint}",
                            variables, constants)
            what = _DESCRIBE.get(type(func), "call of a computed function")
            raise _fail(text, func, what, variables, constants)
        if node.keywords:
            raise _fail(text, node, "keyword argument in", variables, constants)
        f, arity = FUNCTIONS[func.id]
        if len(node.args) != arity:
            raise ExpressionError(f"expression {text!r}: {func.id}() takes {arity} "
                                  f"argument{'s' if arity > 1 else ''}, got {len(node.args)}")
        args = [rec(a) for a in node.args]
        if func.id == "where":
            return lambda env: np.where(np.asarray(args[0](env)) != 0, args[1](env), args[2](env))
        return lambda env: f(*(a(env) for a in args))
    what = _DESCRIBE.get(type(node), f"{type(node).__name__} syntax")
    raise _fail(text, node, what, variables, constants)


def compile_case_expression(case, key: str, text, variables: Sequence[str], *,
                            check_finite: bool = True) -> Expression:
    """Compile the expression of a case file's ``key`` with the file's ``constants``, label it
    with ``key`` (its error messages start with it) and keep it in ``case.functions[key]``.

    Raises
    ------
    ExpressionError
        Prefixed with ``key``.
    """
    try:
        fn = compile_expression(text, variables, case.data.get("constants") or {},
                                check_finite=check_finite)
    except ExpressionError as exc:
        raise ExpressionError(f"{key}: {exc}") from None
    fn.label = key
    case.functions[key] = fn
    return fn
