"""Safe expression parser: valid expressions equal numpy, everything else is refused by name."""

import math

import numpy as np
import pytest

from femkit.case.expressions import FUNCTIONS, compile_expression
from femkit.errors import ExpressionError, InputError

X = np.linspace(0.1, 0.9, 7)
Y = np.linspace(0.2, 0.7, 7)

VALID = [
    ("2*pi**2*sin(pi*x)*sin(pi*y)", lambda x, y: 2 * np.pi**2 * np.sin(np.pi * x) * np.sin(np.pi * y)),
    ("hypot(x, y)**(2/3) * sin(2/3*mod(arctan2(y, x), 2*pi))",
     lambda x, y: np.hypot(x, y) ** (2 / 3) * np.sin(2 / 3 * np.mod(np.arctan2(y, x), 2 * np.pi))),
    ("x**2 - y**2 + log(hypot(x, y))", lambda x, y: x**2 - y**2 + np.log(np.hypot(x, y))),
    ("-x + +y", lambda x, y: -x + y),
    ("exp(-x/y) * sqrt(abs(x - 0.5))", lambda x, y: np.exp(-x / y) * np.sqrt(np.abs(x - 0.5))),
    ("where(x < 0.5, 1, 1e6)", lambda x, y: np.where(x < 0.5, 1.0, 1e6)),
    ("(x > 0.3) * (y <= 0.5)", lambda x, y: ((x > 0.3) & (y <= 0.5)).astype(float)),
    ("0.2 < x < 0.6", lambda x, y: ((0.2 < x) & (x < 0.6)).astype(float)),
    ("atan2(y, x) + arcsin(x) + cosh(y) + tanh(x) + sign(x - 0.5) + floor(3*x)",
     lambda x, y: np.arctan2(y, x) + np.arcsin(x) + np.cosh(y) + np.tanh(x) + np.sign(x - 0.5)
     + np.floor(3 * x)),
    ("minimum(x, y) + maximum(x, y) + e", lambda x, y: np.minimum(x, y) + np.maximum(x, y) + math.e),
]


@pytest.mark.parametrize("text, reference", VALID, ids=[v[0] for v in VALID])
def test_valid_expression_matches_numpy(text, reference):
    f = compile_expression(text)
    np.testing.assert_allclose(f(X, Y), reference(X, Y), rtol=1e-14, atol=0)
    assert f.source == text


@pytest.mark.parametrize("value", [3, 2.5, "4", "pi"], ids=["int", "float", "string-number", "pi"])
def test_constants_broadcast_to_the_shape_of_x(value):
    f = compile_expression(value)
    out = f(np.zeros((4, 3)), np.zeros((4, 3)))
    assert out.shape == (4, 3) and out.dtype == np.float64
    assert np.all(out == float(eval_number(value)))
    assert f.is_constant


def eval_number(v):
    return math.pi if v == "pi" else float(v)


def test_user_constants_and_other_variables():
    f = compile_expression("k*t + c", variables=("t",), constants={"k": 2.0, "c": 1})
    np.testing.assert_array_equal(f(np.array([0.0, 1.0, 2.0])), [1.0, 3.0, 5.0])
    with pytest.raises(ExpressionError, match="clashes"):
        compile_expression("x", constants={"x": 1.0})


UNSAFE = [
    ("__import__('os')", "__import__"),
    ("().__class__", "attribute access"),
    ("open('x')", "'open'"),
    ("x.__class__", "attribute access"),
    ("lambda: 1", "lambda"),
    ("'rm -rf'", "string"),
    ("x[0]", "subscript"),
    ("[x for x in y]", "comprehension"),
    ("sin(x=1)", "keyword"),
    ("np.sin(x)", "attribute access"),
    ("z + 1", "unknown name 'z'"),
    ("x if y else 1", "conditional"),
    ("x and y", "and/or"),
    ("x // 2", "FloorDiv"),
    ("sin", "used as a value"),
    ("sin(x, y)", "takes 1 argument"),
    ("(x := 3)", "assignment"),
    ("f'{x}'", "f-string"),
]


@pytest.mark.parametrize("text, named", UNSAFE, ids=[u[0] for u in UNSAFE])
def test_unsafe_or_unknown_constructs_are_refused_by_name(text, named):
    with pytest.raises(ExpressionError) as info:
        compile_expression(text)
    msg = str(info.value)
    assert named in msg
    assert "\n" not in msg
    assert isinstance(info.value, InputError)


def test_refusal_lists_what_is_allowed_and_suggests_a_close_name():
    with pytest.raises(ExpressionError) as info:
        compile_expression("sinn(pi*x)")
    msg = str(info.value)
    assert "did you mean 'sin'" in msg
    for name in ("x", "y", "pi", "arctan2", "sqrt"):
        assert name in msg


@pytest.mark.parametrize("text", ["1 +", "sin(x", ")", ""], ids=["dangling-op", "unclosed", "paren", "empty"])
def test_malformed_expression(text):
    with pytest.raises(ExpressionError):
        compile_expression(text)


def test_non_finite_values_are_an_error_with_a_location():
    f = compile_expression("log(x)")
    with pytest.raises(ExpressionError, match=r"non-finite values at 1 of 3 points, first at \(x=0"):
        f(np.array([0.0, 1.0, 2.0]), np.zeros(3))
    # a constant overflow is caught when compiling, not hanging on big integers
    with pytest.raises(ExpressionError, match="non-finite"):
        compile_expression("10**10**10")
    # gradients of singular solutions may opt out
    g = compile_expression("1/x", check_finite=False)
    assert np.isinf(g(np.array([0.0]), np.array([0.0]))[0])


def test_every_whitelisted_function_is_callable():
    for name, (_, arity) in FUNCTIONS.items():
        args = ", ".join(["0.5"] * arity)
        out = compile_expression(f"{name}({args})")(X, Y)
        assert out.shape == X.shape, name
