"""A case file's expressions compiled: the numba point functions give the NumPy closures' values
for every whitelisted construct, share common subexpressions, and are cached by their trees."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from femkit.case.compiled_expressions import expression_kernels, module_text, point_function
from femkit.case.expressions import FUNCTIONS, compile_expression

V = ("x", "y", "z")
#: points with edge values: zeros, negatives, > 1 (domain errors), large arguments
POINTS = np.vstack([[[0.0, 0.0, 0.0], [0.3, -0.7, 0.2], [-1.5, 2.0, -0.1], [1.0, 1.0, 1.0],
                     [2.5, -0.0, 3.0], [-3.0, -0.5, 0.0], [1e3, 7.25, -2.0], [0.5, 0.5, 0.5]],
                    np.random.default_rng(0).uniform(-3, 3, (200, 3))])

#: an argument list per arity that takes each function into its domain edges
ARGS = {1: ["x", "y - x", "2*x + 1e-3", "1e3*y"], 2: ["x, y", "y, x", "x, 0", "-x, y"],
        3: ["x < y, x, y", "x, sin(y), 1/x", "0, x, y"]}

WHITELIST = [f"{name}({a})" for name, (_, arity) in FUNCTIONS.items() for a in ARGS[arity]]
OPERATORS = ["x + y - z", "x * y / z", "x / 0", "x ** y", "(-2) ** 0.5", "x ** 2 * y ** 3",
             "-x + +y", "x < y", "x <= y", "x > y", "x >= y", "x == 0", "x != y",
             "0 < x <= 1", "x < y < z", "where(x - 1, x, y)", "pi * e", "k * x + c",
             "3", "1e999 - 1e999", "2*pi**2*sin(pi*x)*sin(pi*y)*sin(pi*z)"]
CONSTANTS = {"k": 2.5, "c": -1.0}


def _compiled(exprs):
    """The generated point function of ``exprs``, compiled, as ``f(x, y, z) -> values``."""
    source = point_function("values", exprs).replace("cache=True, ", "")  # not a file
    space = {"numba": numba, "np": np}
    exec(compile(source, "<generated>", "exec"), space)  # generated from checked trees only
    fn = space["values"]

    def call(x, y, z):
        out = np.empty(len(exprs))
        fn(x, y, z, out)
        return out

    return call


def _numpy(expr, p):
    with np.errstate(all="ignore"):
        return expr._fn(dict(zip(expr.variables, map(np.float64, p))))


@pytest.mark.parametrize("group, texts", [("functions", WHITELIST), ("operators", OPERATORS)],
                         ids=["every-function", "operators-comparisons-where-constants"])
def test_every_whitelisted_construct_compiles_to_the_numpy_value(group, texts):
    """The same ufuncs in the same order of operations: equal (NaN where NumPy gives NaN, inf
    where it gives inf) to 2 units in the last place. numba calls the C library's functions;
    NumPy has its own SIMD versions of some (exp, log10, pow, the inverse and hyperbolic
    functions here), one ulp apart at some points; sin and cos are the C library's in both."""
    exprs = [compile_expression(t, V, CONSTANTS, check_finite=False) for t in texts]
    assert {t.split("(")[0] for t in WHITELIST} == set(FUNCTIONS)
    f = _compiled(exprs)
    for p in POINTS:
        got = f(*p)
        for e, g in zip(exprs, got):
            want = float(_numpy(e, p))
            close = g == want or abs(g - want) <= 2 * np.spacing(abs(want))
            assert close or (math.isnan(g) and math.isnan(want)), (e.source, p, g, want)


def test_common_subexpressions_are_evaluated_once():
    u = compile_expression("sin(pi * x) * sin(pi * y)", V)
    grad = [compile_expression("pi*cos(pi*x)*sin(pi*y)", V),
            compile_expression("pi * sin(pi * x) * cos(pi * y)", V)]
    f = compile_expression("2 * pi**2 * sin(pi * x) * sin(pi * y)", V)
    src = point_function("p", [u, *grad, f])
    assert src.count("np.sin(") == 2 and src.count("np.cos(") == 2


def test_the_module_is_keyed_by_the_tree_not_the_spelling(tmp_path, monkeypatch):
    monkeypatch.setenv("FEMKIT_CACHE_DIR", str(tmp_path))
    a = compile_expression("2*pi*x + y", V)
    b = compile_expression("2 * pi * x  +  y", V)
    assert module_text(a, (), None, fuse_source=False) == module_text(b, (), None, fuse_source=False)
    kernels = expression_kernels(a)
    assert a.fused is kernels and kernels.exact is a and kernels.dim == 2
    module = kernels.module
    assert module.__file__.startswith(str(tmp_path / "expressions"))
    assert expression_kernels(b).module is module          # same text: loaded once
    c = compile_expression("2*pi*x + z", V)
    assert expression_kernels(c).dim == 3                  # uses z: never on a 2D mesh
