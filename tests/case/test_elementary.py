"""The branch-free sin, cos and exp kernels of the compiled expressions against NumPy.

Inside their range the kernels are within 2 ulp of NumPy's functions (1 ulp on all but a few
of them; glibc's are nearly correctly rounded, the kernels' error is about 1 ulp) on millions of arguments
(tiny and subnormal, around 1, multiples of pi/2 and their neighbours, large, negative); the
generated block functions give NumPy's values (to 1 ulp, the same inf / NaN / signed zero) for
arguments beyond the kernels' range, mixed in one block with arguments inside it.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from femkit.case.compiled_expressions import elementary, expression_kernels
from femkit.case.expressions import compile_expression

V = ("x", "y", "z")
#: The kernels' distance from NumPy's functions, in units in the last place.
ULP_BOUND = 2


@numba.njit
def _apply_sin(x, out):
    for i in range(x.shape[0]):
        out[i] = elementary.sin(x[i])


@numba.njit
def _apply_cos(x, out):
    for i in range(x.shape[0]):
        out[i] = elementary.cos(x[i])


@numba.njit
def _apply_exp(x, out):
    for i in range(x.shape[0]):
        out[i] = elementary.exp(x[i])


KERNELS = {"sin": (_apply_sin, np.sin, elementary.SIN_COS_LIMIT),
           "cos": (_apply_cos, np.cos, elementary.SIN_COS_LIMIT),
           "exp": (_apply_exp, np.exp, elementary.EXP_LIMIT)}


def ulps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance in units in the last place (doubles ordered as integers; -0 and +0 are 0 apart)."""
    def ordered(v):
        i = np.ascontiguousarray(v, dtype=np.float64).view(np.int64)
        return np.where(i < 0, np.int64(-2 ** 63) - i, i)
    return np.abs(ordered(a) - ordered(b))


def _arguments(kind: str, limit: float) -> dict:
    rng = np.random.default_rng(2020)
    n = 1_000_000
    sets = {
        "subnormal": rng.integers(-2 ** 40, 2 ** 40, n).astype(np.float64) * 5e-324,
        "tiny": rng.uniform(-1e-8, 1e-8, n),
        "unit": rng.uniform(-1.0, 1.0, n),
        "ten": rng.uniform(-10.0, 10.0, n),
        "large": rng.uniform(-limit, limit, n),
        "log-spread": np.sign(rng.uniform(-1, 1, n)) * np.exp(rng.uniform(-30, np.log(limit), n)),
    }
    if kind == "exp":
        k = np.arange(-1020, 1021, dtype=np.float64)
        sets["multiples-of-ln2"] = k * np.log(2.0)
    else:
        k = np.arange(-60_000, 60_001, dtype=np.float64) * (np.pi / 2)
        sets["multiples-of-pi/2"] = np.concatenate([k, np.nextafter(k, np.inf),
                                                    np.nextafter(k, -np.inf)])
    return sets


@pytest.mark.parametrize("name", list(KERNELS))
def test_kernels_are_within_two_ulp_of_numpy_inside_their_range(name):
    kernel, reference, limit = KERNELS[name]
    for label, x in _arguments(name, limit).items():
        x = x[np.abs(x) <= limit]
        out = np.empty_like(x)
        kernel(x, out)
        worst = int(ulps(out, reference(x)).max())
        assert worst <= ULP_BOUND, f"{name} on {label}: {worst} ulp from NumPy"


def test_signed_zero_and_the_range_limits():
    out = np.empty(2)
    _apply_sin(np.array([0.0, -0.0]), out)
    assert np.array_equal(np.signbit(out), [False, True])
    for name, (kernel, reference, limit) in KERNELS.items():
        x = np.array([limit, -limit, np.nextafter(limit, 0), -np.nextafter(limit, 0)])
        kernel(x, out := np.empty(4))
        assert ulps(out, reference(x)).max() <= ULP_BOUND, name


SPECIAL = np.array([np.inf, -np.inf, np.nan, 1e300, -1e300, 2e5, -1.5e6, 709.0, -709.0, 745.0,
                    -745.5, -800.0, 800.0, 0.0, -0.0, 5e-324, 1e5, -708.0, 708.0, 0.5, -3.0,
                    np.pi, 1e-310])


@pytest.mark.parametrize("text", ["sin(x)", "cos(x)", "exp(x)", "sin(x) * exp(-y) + cos(z)"])
def test_block_functions_give_numpy_values_beyond_the_kernels_range(text):
    """Out-of-range, infinite and NaN arguments mixed with ordinary ones in one block: every
    value is NumPy's (same NaN, infinities and signed zeros; finite values to 2 ulp)."""
    expr = compile_expression(text, V, check_finite=False)
    mod = expression_kernels(expr).module
    rng = np.random.default_rng(5)
    xs = np.concatenate([SPECIAL, rng.uniform(-4, 4, 41)])
    ys, zs = rng.permutation(xs), rng.permutation(xs)
    out = np.empty((1, len(xs)))
    with np.errstate(all="ignore"):
        mod.value_block(xs, ys, zs, len(xs), out)
        ref = expr(xs, ys, zs)
    got = out[0]
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    finite = np.isfinite(ref)
    assert np.array_equal(got[~finite & ~np.isnan(ref)], ref[~finite & ~np.isnan(ref)])
    assert np.array_equal(np.signbit(got[ref == 0]), np.signbit(ref[ref == 0]))
    if text.count("(") == 1:    # one function: each value within 1 ulp
        assert ulps(got[finite], ref[finite]).max() <= ULP_BOUND
    else:
        np.testing.assert_allclose(got[finite], ref[finite], rtol=4e-16, atol=0)


def test_generated_expressions_call_the_kernels_and_keep_the_c_library_for_the_rest():
    from femkit.case.compiled_expressions import module_text

    text = module_text(compile_expression("sin(x) + tanh(y) * exp(x)", V), fuse_source=False)
    assert "fast_sin(" in text and "fast_exp(" in text and "np.tanh(" in text
    assert "np.sin(" in text         # the C library's form, for arguments beyond the kernels
