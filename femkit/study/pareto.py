"""Pareto front of (cost, error) points: the runs no other run beats on both counts.

>>> pareto_front([1.0, 2.0, 3.0, 0.5], [1e-2, 1e-3, 5e-3, 5e-1]).tolist()
[3, 0, 1]
"""

from __future__ import annotations

import numpy as np

__all__ = ["pareto_front"]


def pareto_front(cost, error) -> np.ndarray:
    """Indices of the non-dominated points, ordered by increasing cost.

    A point is dominated when another point has cost ``<=`` and error ``<=`` with at least
    one strict. Points with a non-finite cost or error never belong to the front.

    Parameters
    ----------
    cost, error : array_like
        Same length (e.g. wall time in seconds and an error norm).

    Returns
    -------
    ndarray of int
    """
    c = np.asarray(cost, dtype=float).ravel()
    e = np.asarray(error, dtype=float).ravel()
    if c.shape != e.shape:
        raise ValueError(f"cost and error differ in length ({c.size} vs {e.size})")
    idx = np.flatnonzero(np.isfinite(c) & np.isfinite(e))
    if idx.size == 0:
        return idx
    order = idx[np.lexsort((e[idx], c[idx]))]      # by cost, ties by error
    es = e[order]
    best_before = np.concatenate([[np.inf], np.minimum.accumulate(es)[:-1]])
    return order[es < best_before]
