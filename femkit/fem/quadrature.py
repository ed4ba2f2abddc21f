"""Quadrature rules on triangles and tetrahedra, by name.

A rule is barycentric points ``(q, 3)`` and weights ``(q,)`` summing to 1 (multiply by the
triangle area).  Registry :data:`QUADRATURE`: ``barycentric`` (1 point, degree 1), ``gauss3``
(3 interior points, degree 2), ``gauss6`` (Dunavant, degree 4), ``gauss7`` (Dunavant, degree 5).

Tetrahedra have their own registry :data:`TET_QUADRATURE` (``get_rule(name, dim=3)``):
``barycentric`` (1 point, degree 1), ``gauss4`` (4 points, degree 2; Keast 1986), the
conical-product (Stroud 1971, collapsed Gauss-Jacobi) rules ``stroud8`` (degree 3),
``stroud27`` (degree 5) and ``stroud64`` (degree 7), and ``sym14``, the fully symmetric
14-point rule of degree 5 (orbits of 4, 4 and 6 points, positive weights; exactness checked
monomial by monomial in tests/fem/test_p2_quadrature.py), P2's load rule on tetrahedra. ``sym14``
is not an automatic choice of :func:`rule_for_degree` (which P1's error norms and estimators
use, so their numbers stay those of ``stroud27``) unless asked with ``every=True``.

>>> rule = get_rule("gauss6")
>>> rule.degree, rule.points.shape, round(float(rule.weights.sum()), 15)
(4, (6, 3), 1.0)
>>> get_rule("stroud27", dim=3).points.shape
(27, 4)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..registry import Registry


@dataclass(frozen=True)
class TriangleRule:
    """A quadrature rule: barycentric ``points`` (q, d + 1), ``weights`` (q,) summing to 1,
    exact ``degree`` (``d = 2`` triangles, ``d = 3`` tetrahedra)."""

    name: str
    points: np.ndarray
    weights: np.ndarray
    degree: int
    auto: bool = True

    def physical_points(self, mesh, tri: np.ndarray) -> tuple[np.ndarray, ...]:
        """Coordinates ``(x, y)`` (``(x, y, z)`` on tetrahedra) of the points on each cell,
        each shape (m, q): ``sum_a lambda_a X[tri[:, a]]`` per coordinate, summed vertex by vertex
        in order (the same rounding as a contraction over ``a``, without its (m, d + 1, d) copy)."""
        out = []
        for d in range(mesh.points.shape[1]):
            xd = mesh.points[:, d]
            acc = xd[tri[:, 0], None] * self.points[:, 0]
            for a in range(1, tri.shape[1]):
                acc += xd[tri[:, a], None] * self.points[:, a]
            out.append(acc)
        return tuple(out)


#: Elements per block of the quadrature loops (:func:`blocks`): the (block, q) arrays of one
#: block stay in cache, and a 2M-unknown mesh's quadrature values are never all in memory.
BLOCK = 1 << 15


def blocks(m: int, size: int | None = None) -> list[slice]:
    """Slices of ``range(m)`` in blocks of ``size`` elements (default :data:`BLOCK`; one empty
    slice when ``m = 0``).

    >>> blocks(5, 2)
    [slice(0, 2, None), slice(2, 4, None), slice(4, 5, None)]
    """
    size = size or BLOCK
    return [slice(lo, min(lo + size, m)) for lo in range(0, m, size)] or [slice(0, 0)]


QUADRATURE: Registry[TriangleRule] = Registry("quadrature rule")
TET_QUADRATURE: Registry[TriangleRule] = Registry("tetrahedron quadrature rule")
_REGISTRIES = {2: QUADRATURE, 3: TET_QUADRATURE}


def _orbit3(a: float) -> list[tuple[float, float, float]]:
    b = 1.0 - 2.0 * a
    return [(b, a, a), (a, b, a), (a, a, b)]


def _rule(name, pts, wts, degree, auto=True):
    pts = np.asarray(pts, dtype=np.float64)
    wts = np.asarray(wts, dtype=np.float64)
    _REGISTRIES[pts.shape[1] - 1].register(name, TriangleRule(name, pts, wts / wts.sum(), degree, auto))


def gauss_jacobi(n: int, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Jacobi points and weights on [-1, 1] for the weight ``(1 - t)^alpha`` (beta = 0),
    by Golub-Welsch (eigenvalues of the Jacobi matrix of the monic recurrence; numpy only, so
    importing this module stays cheap). Weights are relative (they sum to 1)."""
    a, b = float(alpha), 0.0
    k = np.arange(n, dtype=np.float64)
    s = 2.0 * k + a + b
    with np.errstate(divide="ignore", invalid="ignore"):
        diag = np.where(s + 2.0 != 0, (b * b - a * a) / (s * (s + 2.0)), 0.0)
    diag[0] = (b - a) / (a + b + 2.0)
    kk = k[1:]
    s1 = 2.0 * kk + a + b
    off = np.sqrt(4.0 * kk * (kk + a) * (kk + b) * (kk + a + b) / (s1 * s1 * (s1 + 1.0) * (s1 - 1.0)))
    t, v = np.linalg.eigh(np.diag(diag) + np.diag(off, 1) + np.diag(off, -1))
    w = v[0] ** 2
    return t, w / w.sum()


def conical_product_points(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Stroud's conical-product rule on the tetrahedron with ``n^3`` points, exact to degree
    ``2 n - 1``: Gauss-Jacobi points in the collapsed coordinates ``x = u``,
    ``y = v (1 - u)``, ``z = w (1 - u)(1 - v)`` (weights ``(1 - u)^2`` and ``(1 - v)`` taken
    into the Jacobi weights). Returns barycentric points (n^3, 4) and weights summing to 1.
    """
    tu, wu = gauss_jacobi(n, 2.0)
    tv, wv = gauss_jacobi(n, 1.0)
    tw, ww = gauss_jacobi(n, 0.0)
    u, v, w = (0.5 * (1.0 + t) for t in (tu, tv, tw))
    U, V, W = np.meshgrid(u, v, w, indexing="ij")
    weights = np.einsum("i,j,k->ijk", wu, wv, ww).ravel()
    x = U.ravel()
    y = (V * (1.0 - U)).ravel()
    z = (W * (1.0 - U) * (1.0 - V)).ravel()
    pts = np.column_stack([1.0 - x - y - z, x, y, z])
    return pts, weights / weights.sum()


_rule("barycentric", [(1 / 3, 1 / 3, 1 / 3)], [1.0], 1)
_rule("gauss3", _orbit3(1 / 6), [1 / 3] * 3, 2)
# Dunavant (1985), degree 4, 6 points
_rule("gauss6", _orbit3(0.445948490915965) + _orbit3(0.091576213509771),
      [0.223381589678011] * 3 + [0.109951743655322] * 3, 4)
# Dunavant (1985), degree 5, 7 points
_rule("gauss7", [(1 / 3, 1 / 3, 1 / 3)] + _orbit3(0.470142064105115) + _orbit3(0.101286507323456),
      [0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3, 5)


# tetrahedra: the centroid; Keast (1986) degree 2; conical products of degree 3, 5 and 7
_rule("barycentric", [(0.25, 0.25, 0.25, 0.25)], [1.0], 1)
_A4, _B4 = 0.1381966011250105, 0.5854101966249685
_rule("gauss4", [(_B4, _A4, _A4, _A4), (_A4, _B4, _A4, _A4), (_A4, _A4, _B4, _A4),
                 (_A4, _A4, _A4, _B4)], [0.25] * 4, 2)
for _n, _deg in ((2, 3), (3, 5), (4, 7)):
    _rule(f"stroud{_n ** 3}", *conical_product_points(_n), _deg)


def _orbit4(a: float) -> list[tuple[float, ...]]:
    b = 1.0 - 3.0 * a
    return [tuple(b if i == j else a for i in range(4)) for j in range(4)]


def _orbit6(a: float) -> list[tuple[float, ...]]:
    b = 0.5 - a
    return [tuple(b if i in (j, k) else a for i in range(4)) for j in range(4) for k in range(j + 1, 4)]


_rule("sym14", _orbit4(0.0927352503108912) + _orbit4(0.3108859192633006) + _orbit6(0.4544962958743504),
      [0.01224884051939366] * 4 + [0.01878132095300264] * 4 + [0.007091003462846911] * 6, 5, auto=False)


def get_rule(name: str, dim: int = 2) -> TriangleRule:
    """The rule registered as ``name`` for triangles (``dim=2``) or tetrahedra (``dim=3``);
    :class:`~femkit.errors.UnknownNameError` (listing the valid names) otherwise."""
    return _REGISTRIES[dim].get(name)


def rule_for_degree(degree: int, dim: int = 2, *, every: bool = False) -> TriangleRule:
    """The cheapest registered rule exact for polynomials of total degree ``degree`` on
    triangles (``dim=2``) or tetrahedra (``dim=3``); ``every``: also among the rules kept out of
    the automatic choice (``sym14``).

    Raises
    ------
    InputError
        No registered rule is exact for that degree (the highest available is named).
    """
    reg = _REGISTRIES[dim]
    rules = sorted((reg.get(n) for n in reg if every or reg.get(n).auto),
                   key=lambda r: (len(r.weights), r.degree))
    for r in rules:
        if r.degree >= degree:
            return r
    best = max(rules, key=lambda r: r.degree)
    raise InputError(f"no quadrature rule of degree {degree}: the highest registered is "
                     f"{best.name!r} (degree {best.degree})")
