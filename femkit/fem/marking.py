"""Dörfler (bulk) marking of elements for adaptive refinement (Dörfler 1996).

>>> dorfler_mark([3.0, 1.0, 2.0, 0.5], 0.5).tolist()      # 9 >= 0.5 * (9 + 1 + 4 + 0.25)
[0]
>>> dorfler_mark([3.0, 1.0, 2.0, 0.5], 0.95).tolist()     # 9 + 4 + 1 >= 0.95 * 14.25
[0, 2, 1]
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import AdaptivityError


def check_theta(theta) -> float:
    """``theta`` as a float in (0, 1]; :class:`~femkit.errors.AdaptivityError` otherwise."""
    try:
        t = float(theta)
    except (TypeError, ValueError):
        raise AdaptivityError(f"theta must be a number in (0, 1], got {theta!r}") from None
    if not (0.0 < t <= 1.0) or math.isnan(t):
        raise AdaptivityError(f"theta must be in (0, 1] (Dörfler marking fraction), got {theta!r}")
    return t


def dorfler_mark(indicators, theta: float) -> np.ndarray:
    """The fewest elements whose squared indicators hold a fraction ``theta`` of the total.

    Parameters
    ----------
    indicators : (m,) array of ``eta_T >= 0``
    theta : float in (0, 1]
        1 marks every element with a non-zero indicator; small values mark few elements.

    Returns
    -------
    ndarray of element ids, largest indicator first: the minimal set ``M`` with
    ``sum_{T in M} eta_T^2 >= theta sum_T eta_T^2`` (one sort, no loop). Empty when every
    indicator is zero.

    Raises
    ------
    AdaptivityError
        ``theta`` outside (0, 1]; negative or non-finite indicators.
    """
    theta = check_theta(theta)
    eta2 = np.asarray(indicators, dtype=np.float64) ** 2
    if eta2.ndim != 1 or not np.isfinite(eta2).all():
        raise AdaptivityError("indicators must be a finite 1-D array")
    if (np.asarray(indicators) < 0).any():
        raise AdaptivityError("indicators must be >= 0")
    total = eta2.sum()
    if total == 0.0:
        return np.zeros(0, dtype=np.int64)
    order = np.argsort(-eta2, kind="stable")
    csum = np.cumsum(eta2[order])
    # the relative slack absorbs round-off in the cumulative sum (theta = 1 must mark all)
    k = int(np.searchsorted(csum, theta * total * (1.0 - 1e-12), side="left")) + 1
    return order[:min(k, len(order))].astype(np.int64)
