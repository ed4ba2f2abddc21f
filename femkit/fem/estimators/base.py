"""The record every a-posteriori error estimator returns, and the registry of estimators by name."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...registry import Registry
from ...warmup_registry import register_kernels

register_kernels("error estimate", "femkit.fem.estimators._kernels", "squares_by_tag", rank=4)

#: name -> estimator ``est(mesh, u, *, kappa, f, neumann, dirichlet_nodes) -> ErrorEstimate``
ESTIMATORS: Registry = Registry("error estimator")


@dataclass(frozen=True)
class ErrorEstimate:
    """Element indicators ``eta_T`` of the energy-norm error and their global sum.

    Attributes
    ----------
    estimator : str
        Registered name (``residual`` or ``zz``).
    indicators : (m,) float64
        ``eta_T >= 0`` per element; the global estimate is ``sqrt(sum eta_T^2)``.
    parts : dict[str, ndarray]
        The squared contributions per element that make up ``eta_T^2`` (e.g. ``volume``, ``jump``,
        ``neumann`` for the residual estimator), for diagnosis.
    """

    estimator: str
    indicators: np.ndarray
    parts: dict = field(default_factory=dict)

    @property
    def energy(self) -> float:
        """Global estimate of the energy-norm error ``(int kappa |grad(u - u_h)|^2)^(1/2)``."""
        return float(np.sqrt(np.sum(self.indicators ** 2)))

    def per_region(self, mesh) -> dict[str, float]:
        """Estimate restricted to each cell region: ``{name or tag: sqrt(sum_T in region eta_T^2)}``.

        Regions are the cell tags; a tag with a name in ``mesh.tag_names`` is reported by name.
        """
        from ..sparsity import NUMBA_THRESHOLD

        tags = np.asarray(mesh.cell_tags)
        if len(tags) >= NUMBA_THRESHOLD:  # the same sums, element by element, compiled
            from ._kernels import squares_by_tag

            uniq = _distinct(tags)
            sums = squares_by_tag(np.ascontiguousarray(tags), uniq,
                                  np.ascontiguousarray(self.indicators, dtype=np.float64))
        else:
            uniq, inv = np.unique(tags, return_inverse=True)
            sums = np.bincount(inv, weights=self.indicators ** 2, minlength=len(uniq))
        names = {}
        for name, tag in mesh.tag_names.items():
            names.setdefault(int(tag), name)   # first name of a tag number wins
        cell_names = {t: names.get(int(t), str(int(t))) for t in uniq}
        return {cell_names[t]: float(np.sqrt(s)) for t, s in zip(uniq, sums)}

    def effectivity(self, true_error: float) -> float:
        """``estimate / true error`` (1 = exact; > 1 overestimates); ``inf`` for a zero error."""
        return self.energy / true_error if true_error > 0 else float("inf")


#: Tags below this are listed by counting (:func:`_distinct`), not by sorting.
_COUNTED_TAGS = 1 << 20


def _distinct(tags: np.ndarray) -> np.ndarray:
    """``np.unique(tags)`` (sorted, the same dtype): by ``np.bincount`` when the tags are small
    non-negative integers (gmsh's physical tags; O(m) instead of a sort of every cell's tag)."""
    if tags.dtype.kind in "iu" and len(tags):
        lo, hi = int(tags.min()), int(tags.max())
        if lo >= 0 and hi < _COUNTED_TAGS:
            return np.flatnonzero(np.bincount(tags, minlength=hi + 1)).astype(tags.dtype)
    return np.unique(tags)
