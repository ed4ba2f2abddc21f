r"""Explicit residual estimator of a P2 solution (triangles and tetrahedra).

The P1 estimator (:mod:`.residual`) with the two terms P2 adds: the element residual holds the
Laplacian of the P2 field (constant on each cell), and the normal flux ``kappa grad u_h . n`` is
linear along each facet, so jumps are integrated by quadrature on the facets:

.. math::

    \eta_T^2 = c_V^2 \frac{h_T^2}{p^2 \kappa_T} \|f + \kappa_T \Delta u_h\|_T^2
      + c_J^2 \sum_{F \subset \partial T \text{ interior}} \frac{h_F}{2 p \kappa_F} \|[\kappa \partial_n u_h]\|_F^2
      + c_J^2 \sum_{F \subset \partial T \text{ Neumann}} \frac{h_F}{p \kappa_T} \|h - \kappa \partial_n u_h\|_F^2

with ``p = 2`` and the weights ``h/p`` of the hp-estimators (Melenk & Wohlmuth 2001, "On residual-based
a posteriori error estimation in hp-FEM", Adv. Comput. Math. 15), ``c_V = 1/pi`` and ``c_J^2 = 1/12``
as for P1, ``h_T`` the longest edge, ``h_F`` the facet's longest edge, ``kappa_F`` the larger
neighbour value. Dirichlet facets (every vertex prescribed) contribute nothing; other boundary facets
not listed as Neumann carry ``kappa du/dn = 0``.

Facet points are placed by the facet's sorted global vertices, so both neighbours evaluate their flux
at the same physical points. NumPy throughout (block-free: (m, d + 1, q) arrays).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ...elements import get_element
from ..coefficients import evaluate_callable
from .._elements import simplex_gradients
from ..dofs import dof_map
from ..quadrature import get_rule, rule_for_degree
from .base import ErrorEstimate
from .geometry import element_kappa

__all__ = ["residual_estimator_p2"]

#: facet rules in the facet's barycentric coordinates: 3-point Gauss-Legendre (degree 5) on an
#: edge, Dunavant's 6-point rule (degree 4) on a face
_EDGE_S = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_EDGE = (np.column_stack([1.0 - _EDGE_S, _EDGE_S]), np.array([5.0, 8.0, 5.0]) / 18.0)


def _facet_rule(dim: int):
    if dim == 2:
        return _EDGE
    rule = get_rule("gauss6")
    return rule.points, rule.weights


def _longest(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    from .residual_faces import _longest as longest

    return longest(points, simplices)


def _facets(mesh):
    """``(facet ids (m, d+1), count per facet)``: facet ``k`` of a cell is opposite vertex ``k``."""
    if mesh.dim == 2:
        from ...mesh.edges import edges

        nodes, ids = edges(mesh)
    else:
        from ...mesh.faces import faces

        nodes, ids = faces(mesh)
    ids = np.asarray(ids, dtype=np.int64)
    return ids, np.bincount(ids.ravel(), minlength=len(nodes))


def _facet_points(cells: np.ndarray, k: int, fbary: np.ndarray) -> np.ndarray:
    """(m, q, d+1) cell barycentric coordinates of the facet rule's points on facet ``k`` of every
    cell, the rule laid on the facet's vertices in ascending global order."""
    m, nv = cells.shape
    others = np.array([a for a in range(nv) if a != k])
    order = np.argsort(cells[:, others], axis=1, kind="stable")      # sorted position -> local
    lam = np.zeros((m, len(fbary), nv))
    rows = np.arange(m)
    for j in range(len(others)):
        lam[rows, :, others[order[:, j]]] = fbary[:, j]
    return lam


def residual_estimator_p2(mesh, u: np.ndarray, *, kappa=1.0, f=0.0, neumann: Sequence = (),
                          dirichlet_nodes: np.ndarray | None = None, c_volume: float = 1 / np.pi,
                          c_jump: float = 1 / np.sqrt(12.0)) -> ErrorEstimate:
    """Residual indicators ``eta_T`` of the P2 solution ``u`` (n_dofs,) (module docstring; the
    arguments as :func:`~.residual.residual_estimator`'s; ``dirichlet_nodes`` are dofs, of which
    the vertices decide which facets are Dirichlet facets)."""
    elem = get_element("P2", mesh.dim)
    p = float(elem.degree)
    dofs = dof_map(mesh, elem)
    u = np.asarray(u, dtype=np.float64)
    kap = element_kappa(mesh, kappa)
    kap = np.broadcast_to(kap, (mesh.n_cells,)) if kap.size == 1 else kap
    G, vol, cells = simplex_gradients(mesh, None)                    # (m, d+1, d)
    ue = u[dofs.cells]                                               # (m, n)
    # Laplacian of u_h: sum_ab (d2u/dlambda_a dlambda_b) G_a . G_b, with d2 phi / dlambda^2 = 4 (vertex a: (a, a);
    # edge (a, b): (a, b) and (b, a))
    nv = mesh.dim + 1
    hess = np.zeros((len(vol), nv, nv))
    hess[:, range(nv), range(nv)] = 4.0 * ue[:, :nv]
    for k, (a, b) in enumerate(elem.local_edges):
        hess[:, a, b] += 4.0 * ue[:, nv + k]
        hess[:, b, a] += 4.0 * ue[:, nv + k]
    lap = np.einsum("mab,mad,mbd->m", hess, G, G)
    rule = rule_for_degree(5, mesh.dim)
    fq = (evaluate_callable(f, *rule.physical_points(mesh, cells), name="f") if callable(f)
          else np.full((len(vol), len(rule.weights)), float(f)))
    r = fq + (kap * lap)[:, None]
    h_t = _longest(mesh.points, cells)
    volume = c_volume ** 2 * h_t ** 2 / (p * p * kap) * vol * ((r * r) @ rule.weights)
    jump, neumann_part = _facet_terms(mesh, hess, ue[:, :nv], G, vol, cells, kap, neumann,
                                      dirichlet_nodes, c_jump ** 2 / p)
    parts = {"volume": volume, "jump": jump, "neumann": neumann_part}
    return ErrorEstimate("residual", np.sqrt(volume + jump + neumann_part), parts)


def _facet_terms(mesh, hess, uv, G, vol, cells, kap, neumann, dirichlet_nodes, weight):
    """The jump and the Neumann parts (each (m,), squared, times ``weight = c_J^2 / p``).

    ``hess`` (m, d+1, d+1): the second derivatives of ``u_h`` in the barycentric coordinates;
    ``uv`` (m, d+1): its vertex values. The gradient of a P2 field is linear in the cell:
    ``du/dlambda_a = sum_b hess[a, b] lambda_b - u_a`` (from ``sum_b lambda_b = 1``), so the flux
    at a facet point is that row times ``G_a . n``, with no basis evaluation."""
    fbary, fw = _facet_rule(mesh.dim)
    ids, count = _facets(mesh)
    m, nv = cells.shape
    n_f, q = len(count), len(fw)
    flux = np.empty((m, nv, q))                                      # outward kappa du/dn
    gnorm = np.linalg.norm(G, axis=2)                                # (m, d+1)
    area = mesh.dim * vol[:, None] * gnorm                           # |F_k| = d |T| |grad lambda_k|
    for k in range(nv):
        lam = _facet_points(cells, k, fbary)                         # (m, q, d+1)
        dl = np.matmul(lam, hess) - uv[:, None, :]                   # (m, q, d+1); hess symmetric
        gn = -np.einsum("mad,md->ma", G, G[:, k]) / gnorm[:, k][:, None]   # G_a . n_k
        flux[:, k] = kap[:, None] * np.einsum("mqa,ma->mq", dl, gn)
    jump_sum = np.zeros((n_f, q))
    for j in range(q):
        jump_sum[:, j] = np.bincount(ids.ravel(), weights=flux[:, :, j].ravel(), minlength=n_f)
    kmax = np.zeros(n_f)
    np.maximum.at(kmax, ids.ravel(), np.repeat(kap, nv))
    f_area = np.zeros(n_f)
    f_area[ids.ravel()] = area.ravel()
    f_h = np.zeros(n_f)
    for k in range(nv):
        f_h[ids[:, k]] = _longest(mesh.points, np.delete(cells, k, axis=1))
    interior = count == 2
    eta_f = np.where(interior, f_h * f_area * ((jump_sum ** 2) @ fw) / kmax, 0.0)
    jump = 0.5 * weight * eta_f[ids].sum(axis=1)
    # boundary facets: h - kappa du/dn (h = 0 unless a Neumann entry covers the facet)
    bnd = count[ids] == 1                                            # (m, d+1)
    if dirichlet_nodes is not None and len(dirichlet_nodes):
        fixed = np.zeros(mesh.n_points, dtype=bool)
        d = np.asarray(dirichlet_nodes, dtype=np.int64)
        fixed[d[d < mesh.n_points]] = True
        for k in range(nv):
            bnd[:, k] &= ~fixed[np.delete(cells, k, axis=1)].all(axis=1)
    elem_i, k_i = np.nonzero(bnd)
    if not len(elem_i):
        return jump, np.zeros(m)
    hq = np.zeros((len(elem_i), q))
    fid = ids[elem_i, k_i]
    keys = _facet_keys(mesh, cells, elem_i, k_i)
    for tags, h in neumann:
        from ..neumann import tagged_facets

        tagged = np.sort(np.asarray(tagged_facets(mesh, tags), dtype=np.int64), axis=1)
        hit = np.isin(keys, _keys(mesh, tagged))
        if not hit.any():
            continue
        if callable(h):
            e_h, k_h = elem_i[hit], k_i[hit]
            xyz = np.empty((len(e_h), q, mesh.dim))                  # (k, q, d)
            for k in range(nv):
                sel = k_h == k
                own = cells[e_h[sel]]
                xyz[sel] = np.einsum("kqa,kad->kqd", _facet_points(own, k, fbary), mesh.points[own])
            hq[hit] = evaluate_callable(h, *np.moveaxis(xyz, 2, 0), name="h")
        else:
            hq[hit] = float(h)
    res = hq - flux[elem_i, k_i]
    val = weight * f_h[fid] * area[elem_i, k_i] * ((res * res) @ fw) / kap[elem_i]
    return jump, np.bincount(elem_i, weights=val, minlength=m)


def _keys(mesh, facets_sorted: np.ndarray) -> np.ndarray:
    n = np.int64(max(mesh.n_points, 1))
    key = facets_sorted[:, 0].astype(np.int64)
    for j in range(1, facets_sorted.shape[1]):
        key = key * n + facets_sorted[:, j]
    return key


def _facet_keys(mesh, cells, elem_i, k_i) -> np.ndarray:
    nv = cells.shape[1]
    sel = cells[elem_i]
    mask = np.arange(nv)[None, :] != k_i[:, None]
    verts = np.sort(sel[mask].reshape(len(elem_i), nv - 1), axis=1)
    return _keys(mesh, verts)
