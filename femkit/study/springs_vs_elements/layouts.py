"""Spring layouts on a triangle mesh with stiffness fitted from Young's modulus: the registry
:data:`SPRING_LAYOUTS` (``layout:`` of the ``springs_vs_elements`` study).

Fitting rule (Van Gelder 1998, "Approximate simulation of elastic membranes by triangulated
spring meshes", J. Graphics Tools 3(2)): the spring on edge ``c`` gets

    k_c = E' * sum_{T incident to c} area(T) / |c|^2,

with ``E'`` the in-plane Young's modulus of the continuum it stands for (plane strain:
``E / (1 - nu^2)``, thickness 1). On an equilateral mesh the lattice then has exactly the
modulus ``E'`` (a triangular lattice of springs ``k`` has ``E = 2 k / sqrt 3``) and Poisson
ratio 1/3 whatever ``nu`` is asked for; on an irregular mesh the rule is an approximation that
no refinement removes (Van Gelder proves no rule is exact in general).

Layouts (the same nodes and lumped masses, the same rule):

* ``edges``: a spring on every mesh edge (:func:`femkit.dynamics.topology.mesh_edges`).
* ``edges_cross``: the mesh edges plus a *cross* spring joining the two vertices opposite every
  interior edge (the other diagonal of the quadrilateral the edge's two triangles form, as the
  shear springs of a cloth grid); each spring of the layout gets half of Van Gelder's stiffness
  on the quadrilateral it spans (a cross spring: the two triangles of its quadrilateral), so a
  uniform dilation stores about the same energy as in ``edges`` (the bulk stiffness is kept:
  ``sum k |c|^2`` is ``3 E' area`` for ``edges``, and the same up to the boundary triangles for
  ``edges_cross``) while shear and bending stiffen.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0.5, 3 ** 0.5 / 2], [1.5, 3 ** 0.5 / 2]]),
...          np.array([[0, 1, 2], [1, 3, 2]]))
>>> springs, k = SPRING_LAYOUTS.get("edges").build(m, 1.0)
>>> springs.tolist(), np.round(k / (3 ** 0.5 / 4), 12).tolist()   # interior edge 1-2: two areas
([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [1.0, 1.0, 2.0, 1.0, 1.0])
>>> s2, k2 = SPRING_LAYOUTS.get("edges_cross").build(m, 1.0)
>>> s2[-1].tolist(), round(float(k2[-1] / (3 ** 0.5 / 12)), 12)   # half of (sqrt3/2) / 3
([0, 3], 1.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...registry import Registry

__all__ = ["SpringLayout", "SPRING_LAYOUTS", "van_gelder", "plane_strain_modulus"]


@dataclass(frozen=True)
class SpringLayout:
    """One layout: ``build(mesh, modulus) -> (springs (s, 2), k (s,))`` and a line saying what
    it is (the report prints it)."""

    build: Callable
    description: str


#: layout name -> :class:`SpringLayout`
SPRING_LAYOUTS: Registry = Registry("spring layout")


def plane_strain_modulus(E: float, nu: float) -> float:
    """The in-plane Young's modulus ``E / (1 - nu^2)`` of a plane-strain body."""
    return float(E) / (1.0 - float(nu) ** 2)


def _edge_areas(points: np.ndarray, triangles: np.ndarray):
    """Unique edges ``(e, 2)`` (sorted pairs, :func:`mesh_edges` order), the summed area of the
    triangles on each, and per edge the opposite vertex of its first and second triangle (-1)."""
    from ...dynamics.topology import mesh_edges

    t = np.asarray(triangles, dtype=np.int64)
    p = np.asarray(points, dtype=float)
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                        - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    edges = mesh_edges(t)
    local = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    opposite = np.concatenate([t[:, 2], t[:, 0], t[:, 1]])
    local.sort(axis=1)
    n = int(t.max()) + 1
    key_all = local[:, 0] * n + local[:, 1]
    key = edges[:, 0].astype(np.int64) * n + edges[:, 1]
    which = np.searchsorted(key, key_all)
    summed = np.bincount(which, weights=np.tile(area, 3), minlength=len(edges))
    order = np.argsort(which, kind="stable")
    first = np.full(len(edges), -1, np.int64)
    second = np.full(len(edges), -1, np.int64)
    w = which[order]
    start = np.r_[True, w[1:] != w[:-1]]
    first[w[start]] = opposite[order][start]
    dup = ~start
    second[w[dup]] = opposite[order][dup]
    return edges, summed, first, second


def van_gelder(points, springs, areas, modulus: float) -> np.ndarray:
    """``k = E' * area / |c|^2`` per spring (``areas``: the triangles the rule counts)."""
    p = np.asarray(points, dtype=float)
    d = p[springs[:, 1]] - p[springs[:, 0]]
    return float(modulus) * np.asarray(areas, float) / np.einsum("ij,ij->i", d, d)


def _edges(mesh, modulus: float):
    edges, summed, _, _ = _edge_areas(mesh.points, mesh.triangles)
    return edges, van_gelder(mesh.points, edges, summed, modulus)


def _edges_cross(mesh, modulus: float):
    edges, summed, first, second = _edge_areas(mesh.points, mesh.triangles)
    inner = second >= 0
    cross = np.sort(np.stack([first[inner], second[inner]], axis=1), axis=1).astype(np.intp)
    springs = np.concatenate([edges, cross])
    areas = np.concatenate([summed, summed[inner]])
    return springs, 0.5 * van_gelder(mesh.points, springs, areas, modulus)


SPRING_LAYOUTS.register("edges", SpringLayout(
    _edges, "a spring on every mesh edge, Van Gelder's stiffness"))
SPRING_LAYOUTS.register("edges_cross", SpringLayout(
    _edges_cross, "mesh edges + a cross spring over every interior edge (the quadrilateral's "
                  "other diagonal), each with half of Van Gelder's stiffness on its quadrilateral"))
