"""Norms, inner products and the scaling every femkit solver verdict is computed with.

A verdict (converged, breakdown, stagnation ...) must not depend on the units of the system:
``A x = b`` and ``(s A) x = s b`` are the same problem for any ``s > 0`` whose entries stay
representable. Three rules make it so (Higham, *Accuracy and Stability of Numerical
Algorithms*, 2nd ed., 2002, sec. 27.5 on scaled norms; the BLAS ``nrm2`` contract):

* **Scaled 2-norms.** ``||v||_2`` is BLAS ``dnrm2`` (scaled accumulation: no overflow of
  ``sum v_i^2`` at ``|v_i| ~ 1e200``, no underflow to 0 at ``|v_i| ~ 1e-170``), never
  ``sqrt(v @ v)``, for residuals, tolerances and the right-hand side.
* **Zero is decided by the data.** ``b = 0`` means every entry of ``b`` is zero
  (``not b.any()``), not that a computed norm underflowed.
* **Normalised iterations.** Iterative methods run on ``b' = 2^-e b`` (and ``x0' = 2^-e x0``)
  with ``2^e`` the binary order of ``max |b_i|`` (:func:`binary_exponent`), so their inner
  products ``r^T z``, ``p^T A p`` stay far from under- and overflow; scaling by a power of two
  is exact, so the iteration is bit-for-bit the one on ``b`` and only the units change.
  Curvature ``p^T A p`` is judged relative to ``||p|| ||A p||`` (:func:`curvature_failure`):
  it is a verdict on the direction, not on the size of the numbers.
"""

from __future__ import annotations

import math

import numpy as np

#: Relative size below which a computed ``p^T A p`` (or ``r^T M r``) cannot be told from zero:
#: the rounding error of an ``n``-term inner product is at most ``n u ||p|| ||A p||``
#: (Higham 2002, eq. 3.5, ``u`` the unit round-off); this factor times ``n`` is the threshold.
ROUNDING_FACTOR = float(np.finfo(np.float64).eps)


def norm2(v) -> float:
    """``||v||_2`` of a real vector by BLAS ``dnrm2`` (scaled: neither over- nor underflows
    while the result is representable).

    Examples
    --------
    >>> import numpy as np
    >>> round(norm2(np.full(4, 1e-170)) * 1e170, 12), round(norm2(np.full(4, 1e200)) / 1e200, 12)
    (2.0, 2.0)
    >>> float(np.linalg.norm(np.full(4, 1e-170)))   # sqrt(v @ v): the squares underflow
    0.0
    """
    from scipy.linalg.blas import dnrm2

    v = np.ascontiguousarray(v, dtype=np.float64).ravel()
    if v.size == 0:
        return 0.0
    return float(dnrm2(v))


def is_zero(v) -> bool:
    """Whether every entry of ``v`` is exactly zero (decided by the entries, not a norm)."""
    return not np.asarray(v).any()


def binary_exponent(v) -> int:
    """``e`` with ``max |v_i|`` in ``[2^(e-1), 2^e)``: ``2^-e v`` has entries of order one
    (0 for a zero or empty vector)."""
    v = np.asarray(v)
    if v.size == 0:
        return 0
    m = float(np.max(np.abs(v)))
    if m == 0.0 or not math.isfinite(m):
        return 0
    return int(math.frexp(m)[1])


def scaled(v: np.ndarray, e: int) -> np.ndarray:
    """``2^e v`` (exact unless it leaves the normal range); ``v`` itself when ``e == 0``."""
    return v if e == 0 else np.ldexp(v, e)


def unscale(value: float, e: int) -> float:
    """``2^e value`` for a scalar (a norm computed on the normalised system)."""
    return ldexp_saturating(value, e) if e else value


def inner_rounding(n: int) -> float:
    """``n u``: relative rounding bound of an ``n``-term inner product (Higham 2002, sec. 3.1)."""
    return max(int(n), 1) * ROUNDING_FACTOR


def curvature_failure(pq: float, p: np.ndarray, q: np.ndarray, *, k: int,
                      what: str = "p^T A p") -> tuple[str, str] | None:
    """Judge a curvature ``pq = p^T q`` (``q = A p``) relative to ``||p|| ||q||``.

    Returns ``None`` when ``pq`` is positive beyond rounding (the direction has positive
    curvature), else ``(reason, message)``: ``"non-finite"``; ``"breakdown"`` for a negative
    curvature beyond rounding (``A`` is indefinite) or one not distinguishable from zero
    (``|pq| <= n u ||p|| ||q||``: ``A`` is singular, or indefinite, along ``p``). A vanishing
    ``p`` (all entries zero) is reported as such. Scale-invariant: the same verdict for ``s A``.
    """
    if not math.isfinite(pq):
        return "non-finite", f"{what} = {pq} at iteration {k}"
    bound = inner_rounding(p.size) * norm2(p) * norm2(q)
    if pq > bound:
        return None
    if is_zero(p):
        return "breakdown", (f"the search direction vanished at iteration {k} ({what} = 0): "
                             f"the preconditioned residual is zero while the residual is not")
    if pq < -bound:
        return "breakdown", (f"indefinite direction: {what} = {pq:.3e} < 0 at iteration {k} "
                             f"(relative to ||p|| ||A p||: {pq / (bound / inner_rounding(p.size)):.3e}); "
                             f"A is not positive definite")
    return "breakdown", (f"vanishing curvature: |{what}| = {abs(pq):.3e} is within rounding "
                         f"(n u ||p|| ||A p|| = {bound:.3e}) at iteration {k}; A is singular or "
                         f"not positive definite along this direction")


def ldexp_saturating(value: float, e: int) -> float:
    """``2^e value`` for a scalar, ``inf`` (not :class:`OverflowError`) when it overflows."""
    try:
        return math.ldexp(value, e)
    except OverflowError:
        return math.copysign(math.inf, value)


def unscale_all(values, e: int) -> np.ndarray:
    """``2^e values`` for a history of normalised norms (``inf`` where it overflows: a
    divergent iteration's history stays honest)."""
    with np.errstate(over="ignore"):
        return np.ldexp(np.asarray(values, dtype=np.float64), e)


def curvature_check(pq: float, p: np.ndarray, q: np.ndarray, *, k: int,
                    what: str = "p^T A p") -> tuple[str, str] | None:
    """:func:`curvature_failure` behind a fast test: ``pq > n u sqrt(p^T p) sqrt(q^T q)`` with
    plain dot products (two extra per iteration); only a pair failing it (or whose dot products
    under- or overflowed) is judged with the scaled norms."""
    if pq > inner_rounding(p.size) * math.sqrt(float(np.dot(p, p)) * float(np.dot(q, q))):
        return None
    return curvature_failure(pq, p, q, k=k, what=what)
