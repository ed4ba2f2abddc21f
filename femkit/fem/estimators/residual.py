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
from .._elements import triangle_geometry
from .geometry import checked_solution, element_fields, element_kappa
from ...warmup_registry import register_kernels, register_threshold

register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("error estimate", "femkit.fem.estimators._kernels", "residual_pass", "slot_fluxes", rank=4)
# the faces of a tetrahedral mesh (:mod:`.residual_faces`, imported only for one)
register_threshold("femkit.fem.estimators.residual_faces", "NUMBA_THRESHOLD")
register_kernels("error estimate", "femkit.fem.estimators._kernels3d", "residual_faces", rank=4,
                 tetrahedra_only=True)

#: Gauss-Legendre points on [0, 1] (3 points, exact to degree 5) for edge integrals of the Neumann data
_GL_S = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GL_W = np.array([5.0, 8.0, 5.0]) / 18.0


def _source_norm_sq(mesh, f, area) -> np.ndarray:
    """``||f||_T^2`` per element (7-point rule of degree 5 for a callable ``f``); ``area`` the
    element areas, or a function giving them (called only when they are needed)."""
    if callable(f):
        rule = rule_for_degree(5)
        fused = source_norm_sq(mesh, f, area, rule)  # compiled (or kept from the error pass)
        if fused is not None:
            return fused
        area = area() if callable(area) else area
        out = np.empty(len(area))
        for s in blocks(len(area)):  # (block, 7) values at a time: in cache, bounded memory
            fv = evaluate_callable(f, *rule.physical_points(mesh, mesh.triangles[s]), name="f")
            out[s] = area[s] * ((fv * fv) @ rule.weights)
        return out
    area = area() if callable(area) else area
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


def _numpy_terms(mesh, u, kappa, f, c_volume: float, c_jump: float):
    """``(volume, jump, kappa, te, count, edge_nodes, fluxes)`` by NumPy over (m, 3) arrays
    (small meshes; the reference of :func:`_compiled_terms`). ``fluxes(elem, k)`` gives the
    length and the flux times the length of local edge ``k`` of triangle ``elem``."""
    fl = element_fields(mesh, u, kappa)
    lens, qlen, jump = _edge_terms(fl, len(fl.edge_nodes), c_jump)
    volume = c_volume ** 2 * lens.max(axis=1) ** 2 * _source_norm_sq(mesh, f, fl.area) / fl.kappa
    return (volume, jump, fl.kappa, fl.tri_edges, fl.edge_count, fl.edge_nodes,
            lambda elem, k: (lens[elem, k], qlen[elem, k]))


def _compiled_terms(mesh, u, kappa, f, c_volume: float, c_jump: float):
    """:func:`_numpy_terms` in compiled passes that allocate only their outputs (large meshes)."""
    from ...mesh.edges import edges
    from . import _kernels

    u = checked_solution(mesh, u)
    kap = element_kappa(mesh, kappa)
    points = np.ascontiguousarray(mesh.points, dtype=np.float64)
    tri = np.ascontiguousarray(mesh.triangles)
    edge_nodes, te = edges(mesh)
    m = mesh.n_triangles
    if callable(f):  # the error pass's source norm when it kept one, written over in place
        fsq, f_sq = _source_norm_sq(mesh, f, lambda: _kernels.triangle_areas(points, tri)), 0.0
        volume = fsq
    else:
        fsq, f_sq = np.empty(0), float(f) ** 2
        volume = np.empty(m)
    jump = np.empty(m)
    count = np.zeros(len(edge_nodes), dtype=np.uint8)
    bad = _kernels.residual_pass(points, tri, u, kap, te, len(edge_nodes), fsq, f_sq,
                                 c_volume ** 2, 0.5 * c_jump ** 2, volume, jump, count)
    if bad:
        triangle_geometry(mesh, None)  # names the degenerate triangles
    return (volume, jump, kap, te, count, edge_nodes,
            lambda elem, k: _kernels.slot_fluxes(points, tri, u, kap, elem, k))


def _neumann_part(mesh, te, count, edge_nodes, fluxes, kap, neumann, dirichlet_nodes,
                  c_jump: float) -> np.ndarray | None:
    """Per element ``c_J^2 h_E / kappa_T ||h - kappa du_h/dn||_E^2`` summed over its boundary
    edges that are not Dirichlet edges; None when there is no such edge."""
    from ...mesh.edges import edge_ids
    from ..neumann import tagged_edges

    is_dir = None
    if dirichlet_nodes is not None:                  # both ends prescribed: a Dirichlet edge
        is_dir = np.zeros(mesh.n_points, dtype=bool)
        is_dir[np.asarray(dirichlet_nodes, dtype=np.int64)] = True
        ends = edge_nodes[np.flatnonzero(count == 1)]
        if (is_dir[ends[:, 0]] & is_dir[ends[:, 1]]).all():
            return None                              # every boundary edge is a Dirichlet edge
    slots = np.flatnonzero(count[te.ravel()] == 1)   # (element, local edge) of the boundary
    bnd = te.ravel()[slots].astype(np.int64)
    order = np.argsort(bnd, kind="stable")           # by edge id
    bnd, slots = bnd[order], slots[order]
    if is_dir is not None:
        keep = ~(is_dir[edge_nodes[bnd, 0]] & is_dir[edge_nodes[bnd, 1]])
        bnd, slots = bnd[keep], slots[keep]
    if not len(bnd):
        return None
    elem, k = slots // 3, slots % 3
    tri = mesh.triangles
    a = mesh.points[tri[elem, (k + 1) % 3]]
    b = mesh.points[tri[elem, (k + 2) % 3]]
    # data h at 3 Gauss points of each Neumann edge (0 where no Neumann entry covers the edge)
    hq = np.zeros((len(bnd), len(_GL_S)))
    for tags, h in neumann:                            # a few entries, not a loop over edges
        ids = edge_ids(mesh, edge_nodes, tagged_edges(mesh, tags))
        pos = np.minimum(np.searchsorted(bnd, ids), len(bnd) - 1)
        ids = pos[bnd[pos] == ids]                     # those among the non-Dirichlet edges
        if not len(ids):
            continue
        if callable(h):
            x = a[ids, 0, None] + _GL_S * (b[ids, 0] - a[ids, 0])[:, None]
            y = a[ids, 1, None] + _GL_S * (b[ids, 1] - a[ids, 1])[:, None]
            hq[ids] = evaluate_callable(h, x, y, name="h")
        else:
            hq[ids] = float(h)
    L, qlen = fluxes(elem, k)
    r = hq - (qlen / L)[:, None]                        # h - kappa du_h/dn at the points
    norm_sq = L * ((r * r) @ _GL_W)
    ke = kap[elem] if len(kap) == mesh.n_triangles else np.full(len(elem), kap[0])
    return np.bincount(elem, weights=c_jump ** 2 * L * norm_sq / ke, minlength=mesh.n_triangles)


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
    if mesh.dim == 3:
        from .residual_faces import residual_terms_3d

        parts = residual_terms_3d(mesh, u, kappa, f, neumann, dirichlet_nodes, c_volume, c_jump)
        return ErrorEstimate("residual", np.sqrt(sum(parts.values())), parts)
    terms = _compiled_terms if mesh.n_cells >= NUMBA_THRESHOLD else _numpy_terms
    volume, jump, kap, te, count, edge_nodes, fluxes = terms(mesh, u, kappa, f, c_volume, c_jump)
    neumann_part = _neumann_part(mesh, te, count, edge_nodes, fluxes, kap, neumann,
                                 dirichlet_nodes, c_jump)
    del te, count, edge_nodes, fluxes
    indicators = volume + jump                          # eta_T^2, then eta_T in place
    if neumann_part is None:
        neumann_part = np.zeros(mesh.n_triangles)       # untouched pages: no memory until read
    else:
        indicators += neumann_part
    np.sqrt(indicators, out=indicators)
    return ErrorEstimate("residual", indicators,
                         {"volume": volume, "jump": jump, "neumann": neumann_part})
