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

Before SymPy sees anything the tree is bounded (:func:`check_bounds`), so that no expression
under the length limit can keep SymPy (or the compiler after it) busy: at most
:data:`MAX_DEPTH` levels of nesting, every number and every constant part (``9**9``) between
:data:`MIN_NUMBER` and :data:`MAX_NUMBER` in size (or zero), and a constant exponent at most
:data:`MAX_EXPONENT` in size (``0*9**9**9`` would otherwise be computed exactly first).

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
import contextlib
import signal
import threading
from typing import Iterator, Mapping

from ...errors import MaterialError

__all__ = ["parse_energy", "check_bounds", "sympy_time_limit", "SYMPY_SECONDS", "FUNCTIONS", "MAX_LENGTH", "MAX_DEPTH", "MAX_NUMBER",
           "MIN_NUMBER", "MAX_EXPONENT"]

#: Longest accepted expression (characters).
MAX_LENGTH = 4000

#: Deepest nesting of operations and calls (``-(-(-s))`` is three levels).
MAX_DEPTH = 100

#: Largest size of a number, or of a constant part, of an energy: the kernels print numbers as
#: exact fractions, whose integers must fit the compiled code's 64-bit integers.
MAX_NUMBER = 1e15

#: Smallest size of a non-zero number or constant part (its fraction's denominator, as above).
MIN_NUMBER = 1e-15

#: Largest size of a constant exponent (``s**64``; a symbolic one, ``s**alpha``, is not bounded).
MAX_EXPONENT = 64

#: Longest SymPy may work on one energy (its checks at rest, or its derivatives for the
#: kernels), seconds: the bundled energies take well under one; a product of dozens of distinct
#: factors would otherwise take minutes.
SYMPY_SECONDS = 30.0


@contextlib.contextmanager
def sympy_time_limit(what: str, seconds: float | None = None) -> Iterator[None]:
    """Within the block, SymPy's work on the energy ``what`` is stopped after ``seconds``
    (default :data:`SYMPY_SECONDS`) with a one-line :class:`MaterialError`. A real-time timer
    (``SIGALRM``) on the main thread; elsewhere, or without ``setitimer``, no limit."""
    seconds = SYMPY_SECONDS if seconds is None else seconds
    if threading.current_thread() is not threading.main_thread() or \
            not hasattr(signal, "setitimer"):
        yield
        return

    def expired(signum, frame):
        raise MaterialError(f"{what}: SymPy did not finish the energy's derivatives within "
                            f"{seconds:g} s; write it with fewer distinct factors or terms")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)

#: Functions an energy may call: name -> number of arguments (SymPy function looked up lazily).
FUNCTIONS: dict[str, int] = {"sqrt": 1, "exp": 1, "log": 1, "sin": 1, "cos": 1, "tanh": 1,
                             "cosh": 1, "sinh": 1, "atan": 1, "abs": 1, "min": 2, "max": 2,
                             "where": 3}

_SYMPY_NAMES = {"sqrt": "sqrt", "exp": "exp", "log": "log", "sin": "sin", "cos": "cos",
                "tanh": "tanh", "cosh": "cosh", "sinh": "sinh", "atan": "atan", "abs": "Abs",
                "min": "Min", "max": "Max"}


def _fail(text: str, what: str, names: Mapping) -> MaterialError:
    shown = text if len(text) <= 80 else f"{text[:60]}...{text[-15:]}"
    return MaterialError(
        f"energy {shown!r}: {what}; allowed: numbers, the names {', '.join(sorted(names))}, pi, E, "
        f"+ - * / ** and the functions {', '.join(sorted(FUNCTIONS))} "
        "(where(a < b, x, y) for a piecewise energy)")


def _short(part: str) -> str:
    return part if len(part) <= 40 else part[:37] + "..."


def check_bounds(text: str, tree: ast.AST, names: Mapping) -> None:
    """Refuse ``tree`` (parsed from ``text``) when it nests deeper than :data:`MAX_DEPTH`, holds a
    number or a constant part outside :data:`MIN_NUMBER` .. :data:`MAX_NUMBER`, or a constant
    exponent above :data:`MAX_EXPONENT`; ``where()`` whose condition is not a comparison.

    Iterative (no recursion, whatever the depth) and in floating point: the constant parts are
    sized, never computed exactly, so this takes microseconds for any text under the length limit.

    Raises
    ------
    MaterialError
        Naming the bound and the part of ``text`` that breaks it.
    """
    value: dict[int, float | None] = {}  # id(node) -> its value if constant, else None
    stack: list = [(tree, 1, False)]
    while stack:
        node, depth, done = stack.pop()
        if depth > MAX_DEPTH:
            raise _fail(text, f"nested deeper than {MAX_DEPTH} levels", names)
        kids = [k for k in ast.iter_child_nodes(node) if isinstance(k, ast.expr)]
        if not done:
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                    and node.func.id == "where" and node.args \
                    and not isinstance(node.args[0], ast.Compare):
                raise _fail(text, "where()'s condition must be one comparison < <= > >=, got "
                            f"{ast.unparse(node.args[0])!r}", names)
            stack.append((node, depth, True))
            stack.extend((k, depth + 1, False) for k in kids)
            continue
        value[id(node)] = v = _constant_value(text, node, value, names)
        if v is not None and v != 0 and not MIN_NUMBER <= abs(v) <= MAX_NUMBER:
            raise _fail(text, f"the number {_short(ast.unparse(node))!r} (about {v:.3g}) is outside "
                        f"{MIN_NUMBER:g} .. {MAX_NUMBER:g} in size", names)


def _constant_value(text: str, node: ast.AST, value: Mapping[int, float | None],
                    names: Mapping) -> float | None:
    """The value of ``node`` when it is a constant (its children's values in ``value``), in
    floating point; None for anything that depends on a name or a call. A constant exponent is
    checked against :data:`MAX_EXPONENT` before the power is taken."""
    import math

    if isinstance(node, ast.Constant):
        v = node.value
        ok = isinstance(v, (int, float)) and not isinstance(v, bool)
        if isinstance(v, int) and ok and v.bit_length() > 1000:
            return math.inf
        return float(v) if ok and math.isfinite(v) else (math.inf if ok else None)
    if isinstance(node, ast.UnaryOp):
        v = value.get(id(node.operand))
        return None if v is None else (-v if isinstance(node.op, ast.USub) else v)
    if not isinstance(node, ast.BinOp):
        return None
    a, b = value.get(id(node.left)), value.get(id(node.right))
    if isinstance(node.op, ast.Pow) and b is not None and abs(b) > MAX_EXPONENT:
        raise _fail(text, f"the exponent {_short(ast.unparse(node.right))!r} (about {b:.3g}) is larger "
                    f"than {MAX_EXPONENT} in size", names)
    if a is None or b is None:
        return None
    try:
        if isinstance(node.op, ast.Add):
            return a + b
        if isinstance(node.op, ast.Sub):
            return a - b
        if isinstance(node.op, ast.Mult):
            return a * b
        if isinstance(node.op, ast.Div):
            return a / b if b != 0 else None  # SymPy's zoo: the finiteness check refuses it
        if isinstance(node.op, ast.Pow):
            return abs(a) ** b if a != 0 or b > 0 else None
    except (OverflowError, ZeroDivisionError):
        return math.inf
    return None


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
    except (RecursionError, MemoryError):  # CPython's own parser nests too
        raise _fail(text, f"nested deeper than {MAX_DEPTH} levels", names) from None
    check_bounds(text, tree, names)
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
