"""Fitted convergence rates: least squares on a log-log scale, with the quality of the fit.

A rate is the slope ``p`` of ``log(err) = p log(x) + c``; for an error against mesh size
``h`` a P1 method on a smooth problem has ``p = 2`` in L2 and ``p = 1`` in the H1 seminorm.
The fit reports the coefficient of determination ``R^2`` and the standard error of the slope
so a reader can tell a clean asymptotic line from a pre-asymptotic scatter.

>>> import numpy as np
>>> h = np.array([0.1, 0.05, 0.025])
>>> fit = fit_rate(h, 3.0 * h**2)
>>> round(fit.slope, 12), round(fit.r2, 12)
(2.0, 1.0)
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError

__all__ = ["RateFit", "fit_rate", "AsymptoticFit", "fit_asymptotic", "local_slopes"]


@dataclass(frozen=True)
class RateFit:
    """A straight line through ``(log x, log y)``.

    Attributes
    ----------
    slope : float
        The fitted rate ``p``.
    intercept : float
        ``c`` in ``log y = p log x + c`` (natural logarithms).
    r2 : float
        Coefficient of determination of the fit on the log-log scale (1 for a perfect line);
        ``nan`` with only two points (any two points lie on a line: R² = 1 would say nothing).
    slope_stderr : float
        Standard error of the slope; ``nan`` with only two points (no degrees of freedom left).
    n : int
        Number of points used.
    """

    slope: float
    intercept: float
    r2: float
    slope_stderr: float
    n: int

    def predict(self, x) -> np.ndarray:
        """The fitted line ``exp(c) x^p`` at ``x``."""
        return np.exp(self.intercept) * np.asarray(x, dtype=float) ** self.slope

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v)
                for k, v in asdict(self).items()}


def fit_rate(x, y) -> RateFit:
    """Least-squares slope of ``log y`` against ``log x`` (:func:`numpy.polyfit`, degree 1).

    Parameters
    ----------
    x, y : array_like
        Positive, finite values of the same length, at least two distinct ``x``.

    Returns
    -------
    RateFit

    Raises
    ------
    InputError
        Fewer than two points, mismatched lengths, or a value that is not positive and finite
        (a logarithm would be undefined).
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.shape != y.shape:
        raise InputError(f"fit_rate: x and y differ in length ({x.size} vs {y.size})")
    if x.size < 2:
        raise InputError(f"fit_rate: need at least 2 points, got {x.size}")
    bad = ~(np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0))
    if bad.any():
        raise InputError(f"fit_rate: values must be positive and finite; bad points at {np.flatnonzero(bad).tolist()}")
    lx, ly = np.log(x), np.log(y)
    sxx = float(np.sum((lx - lx.mean()) ** 2))
    if sxx == 0.0:
        raise InputError("fit_rate: all x values are equal; no slope can be fitted")
    slope, intercept = np.polyfit(lx, ly, 1)
    resid = ly - (slope * lx + intercept)
    ss_res = float(resid @ resid)
    ss_tot = float(np.sum((ly - ly.mean()) ** 2))
    n = int(x.size)
    r2 = (1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0) if n > 2 else float("nan")
    stderr = float(np.sqrt(ss_res / (n - 2) / sxx)) if n > 2 else float("nan")
    return RateFit(float(slope), float(intercept), float(r2), stderr, n)


@dataclass(frozen=True)
class AsymptoticFit:
    """A rate fitted over the asymptotic (finest) part of a sequence; see :func:`fit_asymptotic`.

    Attributes
    ----------
    fit : RateFit
        The fit over the points used.
    used : ndarray
        The ``x`` values used, coarse to fine.
    dropped : ndarray
        The coarse ``x`` values left out (pre-asymptotic).
    local_slopes : ndarray
        Slopes between consecutive points over *all* points, coarse to fine
        (``local_slopes[i]`` joins point ``i`` and ``i + 1``).
    asymptotic : bool
        True when the acceptance test passed; False when even the finest ``min_points`` points
        fail it (the fit over them is returned anyway, flagged).
    """

    fit: RateFit
    used: np.ndarray
    dropped: np.ndarray
    local_slopes: np.ndarray
    asymptotic: bool


def local_slopes(x, y) -> np.ndarray:
    """Slopes ``log(y_i / y_{i+1}) / log(x_i / x_{i+1})`` between consecutive points (order kept).

    >>> local_slopes([0.1, 0.05, 0.025], [1e-2, 2.5e-3, 6.25e-4]).round(12).tolist()
    [2.0, 2.0]
    """
    lx = np.log(np.asarray(x, dtype=float))
    ly = np.log(np.asarray(y, dtype=float))
    return np.diff(ly) / np.diff(lx)


def fit_asymptotic(x, y, *, tol: float = 0.05, min_r2: float = 0.999, min_points: int = 3) -> AsymptoticFit:
    """Fit the rate over the finest points only, dropping coarse (pre-asymptotic) ones.

    Points are ordered coarse to fine (``x`` decreasing). Starting from all of them, the
    coarsest point is dropped until the fit over the rest has ``R^2 >= min_r2`` *and* every
    local slope inside the window lies within ``tol`` of the fitted slope (the line is straight
    there), keeping at least ``min_points`` points (fewer if fewer exist, but at least 2).
    A fit over two points has no R² and is never called asymptotic (nothing tests the line).

    >>> h = 2.0 ** -np.arange(4, 11)
    >>> err = h * (1 + 16 * h)           # order 1 with a large O(h^2) term at coarse h
    >>> round(fit_rate(h, err).slope, 2)  # all points: too steep
    1.15
    >>> a = fit_asymptotic(h, err)
    >>> round(a.fit.slope, 2), a.asymptotic, len(a.dropped)
    (1.05, True, 3)
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    fit_rate(x, y)  # validates (raises InputError on bad input)
    order = np.argsort(-x, kind="stable")
    x, y = x[order], y[order]
    slopes = local_slopes(x, y)
    keep = max(2, min(min_points, x.size))
    for start in range(0, x.size - keep + 1):
        f = fit_rate(x[start:], y[start:])
        window = slopes[start:]
        if f.r2 >= min_r2 and np.all(np.abs(window - f.slope) <= tol):
            return AsymptoticFit(f, x[start:], x[:start], slopes, True)
    start = x.size - keep
    return AsymptoticFit(fit_rate(x[start:], y[start:]), x[start:], x[:start], slopes, False)
