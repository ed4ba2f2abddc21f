r"""Explicit residual estimator, kappa-weighted (Verfürth 1996, 2013; Bernardi & Verfürth 2000).

For P1 and element-wise constant ``kappa`` the element residual is ``f`` (``div(kappa grad u_h) = 0``
inside each triangle; a callable ``kappa`` is taken at the barycentre, as the stiffness assembly does,
so ``grad kappa . grad u_h`` is neglected), and

.. math::

    \eta_T^2 = c_V^2 \frac{h_T^2}{\kappa_T} \|f\|_T^2
      + c_J^2 \sum_{E \subset \partial T \text{ interior}} \frac{h_E}{2\,\kappa_E} \|[\kappa \partial_n u_h]\|_E^2
      + c_J^2 \sum_{E \subset \partial T \text{ Neumann}} \frac{h_E}{\kappa_T} \|h - \kappa \partial_n u_h\|_E^2

with ``h_T`` the longest edge of ``T``, ``h_E`` the length of ``E`` and ``kappa_E`` the larger of
the two neighbours' values (Bernardi & Verfürth 2000: the weights that keep the constants independent
of the contrast of ``kappa`` under their quasi-monotonicity assumption). The 1/2 shares each interior
edge between its two triangles. Dirichlet edges (both ends prescribed) contribute nothing (Dirichlet
data are assumed to be resolved by their nodal interpolant); boundary edges that are neither Dirichlet
nor listed as Neumann carry the natural condition ``kappa du/dn = 0`` and get the mismatch with 0.

Constants. Reliability and efficiency hold up to constants the theory does not fix. With
``c_V = c_J = 1`` (Verfürth's form) the estimate overestimates the energy error 3 to 5.5 times on
femkit's bundled cases. The defaults are ``c_V = 1/pi``, the Poincaré constant of a convex element
(Payne & Weinberger 1960: ``||v - mean v||_T <= h_T/pi ||grad v||_T``), and ``c_J^2 = 1/12``, the
face weight of the Kelly estimator (Kelly, Gago, Zienkiewicz & Babuška 1983; deal.II's
``KellyErrorEstimator`` uses ``h/24`` per side of each face, i.e. ``h_E/12`` per interior edge).
With them the effectivity ``estimate / |||u - u_h|||`` lies in 0.85 ... 1.8 on the bundled cases
(tests/fem/test_estimators.py). Pass ``c_volume=1, c_jump=1`` for the unscaled form.

Scaling: the estimate is unchanged when the domain is scaled (``x -> s x`` with ``f -> f / s^2``,
``h -> h / s``: in 2D the energy norm is scale-free), and scales by ``sqrt(c)``, exactly as the
energy norm, when ``kappa`` and ``f`` are both multiplied by ``c`` (``u`` unchanged).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..coefficients import evaluate_callable
from ..fused import source_norm_sq
from ..quadrature import blocks, rule_for_degree
from ..sparsity import NUMBA_THRESHOLD
from .base import ESTIMATORS, ErrorEstimate
from .geometry import element_fields

#: Gauss-Legendre points on [0, 1] (3 points, exact to degree 5) for edge integrals of the Neumann data
_GL_S = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GL_W = np.array([5.0, 8.0, 5.0]) / 18.0


def _source_norm_sq(mesh, f, area: np.ndarray) -> np.ndarray:
    """``||f||_T^2`` per element (7-point rule of degree 5 for a callable ``f``)."""
    if callable(f):
        rule = rule_for_degree(5)
        fused = source_norm_sq(mesh, f, area, rule)  # compiled (or kept from the error pass)
        if fused is not None:
            return fused
        out = np.empty(len(area))
        for s in blocks(len(area)):  # (block, 7) values at a time: in cache, bounded memory
            fv = evaluate_callable(f, *rule.physical_points(mesh, mesh.triangles[s]), name="f")
            out[s] = area[s] * ((fv * fv) @ rule.weights)
        return out
    return area * float(f) ** 2


def _edge_terms(fl, n_edges: int, c_jump: float):
    """``(lens, qlen, jump)``: edge lengths (m, 3), outward normal flux times length (m, 3) and
    the interior edges' jump term of each element."""
    e, te = fl.e, fl.tri_edges
    lens = np.hypot(e[..., 0], e[..., 1])                  # (m, 3)
    # outward normal flux kappa grad u_h . n times the edge length, per (element, local edge):
    # for a counter-clockwise triangle the outward normal of e = (ex, ey) is (ey, -ex) / |e|
    sigma = fl.kappa[:, None] * fl.grad
    qlen = sigma[:, None, 0] * e[..., 1] - sigma[:, None, 1] * e[..., 0]          # (m, 3)
    jump_len = np.bincount(te.ravel(), weights=qlen.ravel(), minlength=n_edges)   # [flux] * |E|
    kmax = np.zeros(n_edges)
    np.maximum.at(kmax, te.ravel(), np.repeat(fl.kappa, 3))
    # h_E ||J||_E^2 / kappa_E with ||J||_E^2 = J^2 h_E and J = jump_len / h_E: jump_len^2 / kappa_E
    eta_edge = np.where(fl.edge_count == 2, jump_len ** 2 / kmax, 0.0)
    return lens, qlen, 0.5 * c_jump ** 2 * eta_edge[te].sum(axis=1)


@ESTIMATORS.register("residual")
def residual_estimator(mesh, u: np.ndarray, *, kappa=1.0, f=0.0, neumann: Sequence = (),
                       dirichlet_nodes: np.ndarray | None = None, c_volume: float = 1 / np.pi,
                       c_jump: float = 1 / np.sqrt(12.0)) -> ErrorEstimate:
    """Residual indicators ``eta_T`` of the P1 solution ``u`` (see the module docstring).

    Parameters
    ----------
    mesh : Mesh
    u : (n,) nodal values of the discrete solution.
    kappa : coefficient as in :func:`~femkit.fem.coefficients.element_coefficient`.
    f : float or callable f(x, y) (f(x, y, z) on tetrahedra; faces replace edges there,
        :mod:`.residual_faces`), the source.
    neumann : sequence of (tags, h): outward flux data ``kappa du/dn = h`` as given to the problem.
    dirichlet_nodes : node ids where ``u`` was prescribed (a boundary edge with both ends among
        them is a Dirichlet edge); ``None``: no Dirichlet edge (every boundary edge is Neumann).
    c_volume, c_jump : float
        Weights of the volume and of the edge (jump and Neumann) terms (module docstring).

    Returns
    -------
    ErrorEstimate
        ``parts``: ``volume``, ``jump``, ``neumann`` (each ``(m,)``, squared).
    """
    from ...mesh.edges import edge_ids
    from ..neumann import tagged_edges

    if mesh.dim == 3:
        from .residual_faces import residual_terms_3d

        parts = residual_terms_3d(mesh, u, kappa, f, neumann, dirichlet_nodes, c_volume, c_jump)
        return ErrorEstimate("residual", np.sqrt(sum(parts.values())), parts)
    fl = element_fields(mesh, u, kappa)
    e, te, count = fl.e, fl.tri_edges, fl.edge_count
    n_edges = len(fl.edge_nodes)
    if mesh.n_cells >= NUMBA_THRESHOLD:  # the same numbers in one compiled pass
        from ._kernels import residual_edges

        lens, qlen, jump = residual_edges(e, fl.grad, fl.kappa, te, count, n_edges,
                                          0.5 * c_jump ** 2)
    else:
        lens, qlen, jump = _edge_terms(fl, n_edges, c_jump)
    h_T = lens.max(axis=1)
    volume = c_volume ** 2 * h_T ** 2 * _source_norm_sq(mesh, f, fl.area) / fl.kappa

    # boundary edges: Neumann mismatch unless both ends are Dirichlet nodes
    bnd = np.flatnonzero(count == 1)
    is_dir = np.zeros(mesh.n_points, dtype=bool)
    if dirichlet_nodes is not None:
        is_dir[np.asarray(dirichlet_nodes, dtype=np.int64)] = True
    bnd = bnd[~(is_dir[fl.edge_nodes[bnd, 0]] & is_dir[fl.edge_nodes[bnd, 1]])]
    neumann_part = np.zeros(mesh.n_triangles)
    if len(bnd):
        # data h at 3 Gauss points of each Neumann edge (0 where no Neumann entry covers the edge)
        owner_slot = np.flatnonzero(count[te.ravel()] == 1)
        slot_of_edge = np.full(n_edges, -1, dtype=np.int64)
        slot_of_edge[te.ravel()[owner_slot]] = owner_slot
        slot = slot_of_edge[bnd]
        elem, k = slot // 3, slot % 3
        tri = mesh.triangles
        a = mesh.points[tri[elem, (k + 1) % 3]]
        b = mesh.points[tri[elem, (k + 2) % 3]]
        hq = np.zeros((len(bnd), len(_GL_S)))
        pos_of_edge = np.full(n_edges, -1, dtype=np.int64)
        pos_of_edge[bnd] = np.arange(len(bnd))
        for tags, h in neumann:                            # a few entries, not a loop over edges
            ids = pos_of_edge[edge_ids(mesh, fl.edge_nodes, tagged_edges(mesh, tags))]
            ids = ids[ids >= 0]
            if not len(ids):
                continue
            if callable(h):
                x = a[ids, 0, None] + _GL_S * (b[ids, 0] - a[ids, 0])[:, None]
                y = a[ids, 1, None] + _GL_S * (b[ids, 1] - a[ids, 1])[:, None]
                hq[ids] = evaluate_callable(h, x, y, name="h")
            else:
                hq[ids] = float(h)
        L = lens[elem, k]
        r = hq - (qlen[elem, k] / L)[:, None]               # h - kappa du_h/dn at the points
        norm_sq = L * ((r * r) @ _GL_W)
        neumann_part = np.bincount(elem, weights=c_jump ** 2 * L * norm_sq / fl.kappa[elem],
                                   minlength=mesh.n_triangles)
    total = volume + jump + neumann_part
    return ErrorEstimate("residual", np.sqrt(total),
                         {"volume": volume, "jump": jump, "neumann": neumann_part})
