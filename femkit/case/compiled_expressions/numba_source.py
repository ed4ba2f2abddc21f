"""numba source of a set of expressions, generated from their checked trees.

:func:`point_function` prints one function ``name(x, y, z, out)`` that writes the value of each
expression at the point into ``out``. It walks the same checked tree
:func:`femkit.case.expressions.compile_expression` built its NumPy closures from, and prints each
node as the scalar form of the very operation the closure applies: the same NumPy ufunc (by its
name: ``np.sin``, ``np.power``, ``np.remainder``, ...; numba compiles them for scalars),
comparisons as ``1.0``/``0.0``, ``where(c, a, b)`` as ``a if c != 0 else b``. Numbers and named
constants are printed as their float values; division by zero and domain errors give inf/NaN as
in NumPy (the function is compiled with numba's ``error_model="numpy"``).

Common subexpressions are shared exactly: every node is printed once as a temporary named by
its text, and a structurally identical node (``sin(pi * x)`` in ``u``, in ``du/dy`` and in ``f``)
reuses it. Nothing is reordered or simplified, so each value is rounded as the NumPy closures
round it, except, with ``fast``, ``sin``, ``cos`` and ``exp``: those are the inlined kernels of
:mod:`.elementary` (within 2 ulp of NumPy's), and :func:`block_function` prints the loop over a
block of points that LLVM vectorises; arguments beyond the kernels' range take the C library's
function, as without ``fast``.

>>> from femkit.case.expressions import compile_expression
>>> u = compile_expression("sin(pi * x) * sin(pi * y)", ("x", "y", "z"))
>>> f = compile_expression("2*pi**2*sin(pi*x)*sin(pi*y)", ("x", "y", "z"))
>>> print(point_function("both", [u, f]))  # doctest: +NORMALIZE_WHITESPACE
@numba.njit(cache=True, nogil=True, error_model="numpy")
def both(x, y, z, out):  # pragma: no cover - compiled
    t0 = (3.141592653589793 * x)
    t1 = np.sin(t0)
    t2 = (3.141592653589793 * y)
    t3 = np.sin(t2)
    t4 = (t1 * t3)
    t5 = np.power(3.141592653589793, 2.0)
    t6 = (2.0 * t5)
    t7 = (t6 * t1)
    t8 = (t7 * t3)
    out[0] = t4
    out[1] = t8
"""

from __future__ import annotations

import ast
import math
from typing import Sequence

from ..expressions import _BINOPS, _COMPARE, FUNCTIONS

__all__ = ["point_function", "COORDINATES", "KERNELS", "KERNEL_IMPORT"]

#: NumPy functions printed as the inlined branch-free kernels of :mod:`.elementary`:
#: ufunc name -> (kernel, its range check), as the generated module imports them.
KERNELS = {"sin": ("fast_sin", "in_trig_range"), "cos": ("fast_cos", "in_trig_range"),
           "exp": ("fast_exp", "in_exp_range")}
#: The import line a generated module needs for :data:`KERNELS`.
KERNEL_IMPORT = ("from femkit.case.compiled_expressions.elementary import "
                 "cos as fast_cos, exp as fast_exp, in_exp_range, in_trig_range, sin as fast_sin")

#: The parameters of a generated point function, in the order of an expression's variables.
COORDINATES = ("x", "y", "z")

_UNARY = {ast.USub: "-", ast.UAdd: "+"}
_COMPARE_TEXT = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==",
                 ast.NotEq: "!="}
assert set(_COMPARE_TEXT) == set(_COMPARE)


def _literal(value: float) -> str:
    value = float(value)
    if math.isnan(value):
        return "np.nan"
    if math.isinf(value):
        return "np.inf" if value > 0 else "(-np.inf)"
    return repr(value) if value >= 0 else f"({value!r})"


class _Printer:
    """Prints trees into lines ``tK = ...``, one per distinct node."""

    def __init__(self, fast: bool = False):
        self.lines: list[str] = []
        self.checks: list[str] = []     # the range checks of the kernels' arguments
        self.fast = fast
        self._temps: dict[str, str] = {}

    def _temp(self, text: str) -> str:
        name = self._temps.get(text)
        if name is None:
            name = self._temps[text] = f"t{len(self._temps)}"
            self.lines.append(f"    {name} = {text}")
        return name

    def value(self, expr) -> str:
        """The name (or literal) holding ``expr``'s value."""
        coords = dict(zip(expr.variables, COORDINATES))
        return self._node(expr.tree, coords, expr.names)

    def _node(self, node, coords, names) -> str:
        rec = lambda n: self._node(n, coords, names)  # noqa: E731
        if isinstance(node, ast.Constant):
            return _literal(node.value)
        if isinstance(node, ast.Name):
            if node.id in coords:
                return coords[node.id]
            return _literal(names[node.id])
        if isinstance(node, ast.BinOp):
            a, b = rec(node.left), rec(node.right)
            if isinstance(node.op, ast.Pow):  # np.power, as the closure: no Python folding
                return self._temp(f"np.power({a}, {b})")
            return self._temp(f"({a} {_BINOPS[type(node.op)][1]} {b})")
        if isinstance(node, ast.UnaryOp):
            return self._temp(f"({_UNARY[type(node.op)]}{rec(node.operand)})")
        if isinstance(node, ast.Compare):
            parts = [rec(node.left)] + [rec(c) for c in node.comparators]
            tests = " and ".join(f"({a} {_COMPARE_TEXT[type(op)]} {b})"
                                 for op, a, b in zip(node.ops, parts, parts[1:]))
            return self._temp(f"(1.0 if {tests} else 0.0)")
        if isinstance(node, ast.Call):
            name = node.func.id
            args = [rec(a) for a in node.args]
            if name == "where":
                return self._temp(f"({args[1]} if {args[0]} != 0.0 else {args[2]})")
            ufunc = FUNCTIONS[name][0].__name__
            if self.fast and ufunc in KERNELS:   # the inlined polynomial, its range checked
                kernel, check = KERNELS[ufunc]
                self.checks.append(f"{check}({args[0]})")
                return self._temp(f"{kernel}({args[0]})")
            return self._temp(f"np.{ufunc}({', '.join(args)})")
        raise AssertionError(f"unchecked node {type(node).__name__}")  # the parser refused it


def point_function(name: str, expressions: Sequence, *, fast: bool = False) -> str:
    """Source of the numba function ``name(x, y, z, out)`` writing ``out[i]`` = the value of
    ``expressions[i]`` (checked :class:`~femkit.case.expressions.Expression` objects, whose
    variables are taken as ``x, y, z`` in order) at the point.

    With ``fast``, ``sin``, ``cos`` and ``exp`` are the inlined kernels of :mod:`.elementary`
    (:data:`KERNELS`; the module needs :data:`KERNEL_IMPORT`) and, when the expressions call one,
    the text holds two functions: ``name_libm``, the plain form, and ``name``, which evaluates
    the kernels and, when one of their arguments is outside the range they handle, the point
    again by ``name_libm`` (so inf, NaN and huge arguments give NumPy's values).
    """
    printer = _Printer(fast=fast)
    results = [printer.value(e) for e in expressions]
    body = printer.lines + [f"    out[{i}] = {r}" for i, r in enumerate(results)]
    if not printer.checks:
        return "\n".join(_head(name, "x, y, z, out") + (body or ["    pass"]))
    body += [f"    if ({' & '.join(dict.fromkeys(printer.checks))}) == 0:  # the C library's",
             f"        {name}_libm(x, y, z, out)"]
    return "\n".join([point_function(f"{name}_libm", expressions), "", "",
                      *_head(name, "x, y, z, out"), *body])


def block_function(name: str, point: str, expressions: Sequence, *, fast: bool = True) -> str:
    """Source of the numba function ``name(xs, ys, zs, n, out)`` writing ``out[i, p]`` = the
    value of ``expressions[i]`` at the point ``(xs[p], ys[p], zs[p])``, ``p < n``.

    The loop over the points is straight-line code (the :mod:`.elementary` kernels, their range
    checks folded into a minimum), which LLVM vectorises. When an argument was outside the
    kernels' range the block is evaluated again point by point by ``point`` (the
    :func:`point_function` of the same expressions with ``fast``), which takes the C library's
    value where the kernels do not apply. Without ``fast``: the C library's functions throughout
    (``point`` unused).
    """
    printer = _Printer(fast=fast)
    results = [printer.value(e) for e in expressions]
    checks = list(dict.fromkeys(printer.checks))
    body = ["    ok = 1", "    for p in range(n):", "        x = xs[p]", "        y = ys[p]",
            "        z = zs[p]", *("    " + line for line in printer.lines),
            *(f"        out[{i}, p] = {r}" for i, r in enumerate(results)),
            *(f"        ok = min(ok, {c})" for c in checks)]
    if checks:
        body += ["    if ok == 0:  # an argument beyond the kernels: point by point",
                 "        v = np.empty(out.shape[0])", "        for p in range(n):",
                 f"            {point}(xs[p], ys[p], zs[p], v)",
                 "            for i in range(out.shape[0]):", "                out[i, p] = v[i]"]
    return "\n".join(_head(name, "xs, ys, zs, n, out") + body)


def _head(name: str, args: str) -> list[str]:
    return ['@numba.njit(cache=True, nogil=True, error_model="numpy")',
            f"def {name}({args}):  # pragma: no cover - compiled"]
