"""Branch-free sin, cos and exp for compiled expressions: inlined polynomials LLVM can vectorise.

numba compiles ``np.sin`` / ``np.cos`` / ``np.exp`` of a scalar into a call of the C library
(without Intel's SVML no vector form exists), so a loop over quadrature points that evaluates
them runs one call at a time; at ~20-35 ns per call they were most of an error pass. The kernels
here are straight-line code (selects, no branches, no calls), inlined into the generated point
functions, so a loop over a block of points is vectorised by LLVM, and a scalar call costs a
few nanoseconds.

- Argument reduction (Cody & Waite 1980): ``k = rint(x * 2/pi)`` by the ``1.5 * 2^52`` rounding
  trick, ``r = x - k pi/2`` with ``pi/2`` split in three doubles (the 3-part split of SLEEF,
  Shibata & Petrogalli 2020) and fused multiply-adds: the first product is exact, so ``r`` keeps
  its relative precision near multiples of ``pi/2``; ``exp`` reduces ``x = k ln 2 + r``.
- Polynomials on the reduced range: ``sin`` / ``cos`` on ``[-pi/4, pi/4]`` and ``exp`` on
  ``[-ln2/2, ln2/2]`` with the minimax coefficients of fdlibm (Sun Microsystems 1993:
  ``k_sin.c``, ``k_cos.c``, ``e_exp.c``; the Cephes library's ``sin.c`` / ``exp.c`` (Moshier
  1989) use the same forms), ``2^k`` assembled from its exponent bits.

Accuracy (tests/case/test_elementary.py, millions of arguments against NumPy): within 2 ulp
inside the range each kernel handles, :data:`SIN_COS_LIMIT` (``|x| <= 1e5``) and
:data:`EXP_LIMIT` (``|x| <= 708``). Outside it (and for inf / NaN) a kernel's value is
meaningless: a caller checks :func:`in_trig_range` / :func:`in_exp_range` (branch-free too, so
the check vectorises with the kernel) and evaluates the C library's function instead, which
is what the generated expressions do (:mod:`.numba_source`).

>>> import numpy as np
>>> x = np.linspace(-50.0, 50.0, 1001)
>>> bool(np.allclose([sin(v) for v in x], np.sin(x), rtol=0, atol=1e-15))
True
"""

from __future__ import annotations

import numba
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from ...fem.fused.templates import fma as _fma

__all__ = ["sin", "cos", "exp", "in_trig_range", "in_exp_range", "SIN_COS_LIMIT", "EXP_LIMIT",
           "KERNELS"]

#: ``|x|`` up to which :func:`sin` and :func:`cos` are accurate (beyond: the C library's).
SIN_COS_LIMIT = 1.0e5
#: ``|x|`` up to which :func:`exp` is accurate and its result a normal number.
EXP_LIMIT = 708.0

_ROUND = 6755399441055744.0            # 1.5 * 2^52: (v + _ROUND) - _ROUND = rint(v), |v| < 2^51
_TWO_OVER_PI = 0.6366197723675814
_PIO2_HI = 1.5707963267948966          # pi/2 = HI + MID + LO (about 160 bits)
_PIO2_MID = 6.123233995736766e-17
_PIO2_LO = -1.4973849048591698e-33
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
_INV_LN2 = 1.44269504088896338700e+00
_LN2_HI, _LN2_LO = 6.93147180369123816490e-01, 1.90821492927058770002e-10
_P1, _P2, _P3 = 1.66666666666666019037e-01, -2.77777777770155933842e-03, 6.61375632143793436117e-05
_P4, _P5 = -1.65339022054652515390e-06, 4.13813679705723846039e-08


@intrinsic
def _from_bits(typingctx, bits):  # pragma: no cover - compiled
    """The float64 whose bit pattern is the int64 ``bits``."""
    sig = types.float64(types.int64)

    def codegen(context, builder, signature, args):
        v = context.cast(builder, args[0], signature.args[0], types.int64)
        return builder.bitcast(v, ir.DoubleType())

    return sig, codegen


@numba.njit(cache=True, inline="always", error_model="numpy")
def _reduce(x):  # pragma: no cover - compiled
    """``(r, t, q)``: ``x = k pi/2 + r + t`` with ``r + t`` a double-double (``|t| <= ulp(r)/2``),
    ``|r| <= pi/4`` (about) and ``q = k mod 4``."""
    k = (x * _TWO_OVER_PI + _ROUND) - _ROUND
    a = _fma(-k, _PIO2_HI, x)                       # exact: k * HI is formed without rounding
    b = k * _PIO2_MID
    b_err = _fma(k, _PIO2_MID, -b)                  # k * MID = b + b_err exactly
    r = a - b
    bv = r - a                                      # a - b = r + ((a - (r - bv)) - (b + bv)) exactly
    t = ((a - (r - bv)) - (b + bv)) - b_err - k * _PIO2_LO
    hi = r + t
    return hi, (r - hi) + t, numba.int64(k) & 3


@numba.njit(cache=True, inline="always", error_model="numpy")
def _sin_cos(r, t):  # pragma: no cover - compiled
    """``(sin(r + t), cos(r + t))`` for ``|r| <= pi/4`` and the tail ``t`` (fdlibm's
    ``__kernel_sin`` / ``__kernel_cos`` with their ``y``)."""
    z = r * r
    v = z * r
    w = _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))
    s = r - ((z * (0.5 * t - v * w) - t) - v * _S1)
    p = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    c = 1.0 - hz
    c = c + (((1.0 - c) - hz) + (z * p - r * t))
    return s, c


@numba.njit(cache=True, inline="always", error_model="numpy")
def sin(x):  # pragma: no cover - compiled
    """``sin(x)`` for ``|x| <= SIN_COS_LIMIT`` (finite), branch-free."""
    r, t, q = _reduce(x)
    s, c = _sin_cos(r, t)
    v = c if q & 1 else s
    v = -v if q & 2 else v
    return v if x != 0.0 else x                    # sin(-0) = -0


@numba.njit(cache=True, inline="always", error_model="numpy")
def cos(x):  # pragma: no cover - compiled
    """``cos(x)`` for ``|x| <= SIN_COS_LIMIT`` (finite), branch-free."""
    r, t, q = _reduce(x)
    s, c = _sin_cos(r, t)
    v = s if q & 1 else c
    return -v if (q + 1) & 2 else v


@numba.njit(cache=True, inline="always", error_model="numpy")
def exp(x):  # pragma: no cover - compiled
    """``exp(x)`` for ``|x| <= EXP_LIMIT``, branch-free (fdlibm's ``__ieee754_exp``)."""
    k = (x * _INV_LN2 + _ROUND) - _ROUND
    hi = x - k * _LN2_HI                            # exact: LN2_HI has 32 bits, |k| < 2^11
    lo = k * _LN2_LO
    r = hi - lo
    t = r * r
    c = r - t * (_P1 + t * (_P2 + t * (_P3 + t * (_P4 + t * _P5))))
    y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
    return y * _from_bits((numba.int64(k) + 1023) << 52)


@numba.njit(cache=True, inline="always")
def in_trig_range(x):  # pragma: no cover - compiled
    """1 when :func:`sin` / :func:`cos` handle ``x``, else 0 (also for inf and NaN)."""
    return 1 if abs(x) <= SIN_COS_LIMIT else 0


@numba.njit(cache=True, inline="always")
def in_exp_range(x):  # pragma: no cover - compiled
    """1 when :func:`exp` handles ``x``, else 0 (also for inf and NaN)."""
    return 1 if abs(x) <= EXP_LIMIT else 0


#: NumPy function name -> (kernel, range check) for the generated expressions.
KERNELS = {"sin": ("sin", "in_trig_range"), "cos": ("cos", "in_trig_range"),
           "exp": ("exp", "in_exp_range")}
