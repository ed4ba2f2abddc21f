"""Quadrature rules on triangles, by name.

A rule is barycentric points ``(q, 3)`` and weights ``(q,)`` summing to 1 (multiply by the
triangle area).  Registry :data:`QUADRATURE`: ``barycentric`` (1 point, degree 1), ``gauss3``
(3 interior points, degree 2), ``gauss6`` (Dunavant, degree 4), ``gauss7`` (Dunavant, degree 5).

>>> rule = get_rule("gauss6")
>>> rule.degree, rule.points.shape, round(float(rule.weights.sum()), 15)
(4, (6, 3), 1.0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..registry import Registry


@dataclass(frozen=True)
class TriangleRule:
    """A quadrature rule: barycentric ``points`` (q, 3), ``weights`` (q,) summing to 1, exact ``degree``."""

    name: str
    points: np.ndarray
    weights: np.ndarray
    degree: int

    def physical_points(self, mesh, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates ``(x, y)`` of the points on each triangle, each shape (m, q)."""
        p = mesh.points[tri]  # (m, 3, 2)
        xy = np.einsum("qa,mad->dmq", self.points, p)
        return xy[0], xy[1]


QUADRATURE: Registry[TriangleRule] = Registry("quadrature rule")


def _orbit3(a: float) -> list[tuple[float, float, float]]:
    b = 1.0 - 2.0 * a
    return [(b, a, a), (a, b, a), (a, a, b)]


def _rule(name, pts, wts, degree):
    pts = np.asarray(pts, dtype=np.float64)
    wts = np.asarray(wts, dtype=np.float64)
    QUADRATURE.register(name, TriangleRule(name, pts, wts / wts.sum(), degree))


_rule("barycentric", [(1 / 3, 1 / 3, 1 / 3)], [1.0], 1)
_rule("gauss3", _orbit3(1 / 6), [1 / 3] * 3, 2)
# Dunavant (1985), degree 4, 6 points
_rule("gauss6", _orbit3(0.445948490915965) + _orbit3(0.091576213509771),
      [0.223381589678011] * 3 + [0.109951743655322] * 3, 4)
# Dunavant (1985), degree 5, 7 points
_rule("gauss7", [(1 / 3, 1 / 3, 1 / 3)] + _orbit3(0.470142064105115) + _orbit3(0.101286507323456),
      [0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3, 5)


def get_rule(name: str) -> TriangleRule:
    """The rule registered as ``name``; :class:`~femkit.errors.UnknownNameError` otherwise."""
    return QUADRATURE.get(name)


def rule_for_degree(degree: int) -> TriangleRule:
    """The cheapest registered rule exact for polynomials of total degree ``degree``.

    Raises
    ------
    InputError
        No registered rule is exact for that degree (the highest available is named).
    """
    rules = sorted((QUADRATURE.get(n) for n in QUADRATURE), key=lambda r: (len(r.weights), r.degree))
    for r in rules:
        if r.degree >= degree:
            return r
    best = max(rules, key=lambda r: r.degree)
    raise InputError(f"no quadrature rule of degree {degree}: the highest registered is "
                     f"{best.name!r} (degree {best.degree})")
