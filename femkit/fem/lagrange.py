"""The Poisson problem's pieces for any Lagrange element (P2): load, Neumann flux, Dirichlet dofs,
dof weights, error norms.

P1 keeps its own, faster routines (:mod:`femkit.fem.load`, :mod:`femkit.fem.neumann`,
:mod:`femkit.fem.norms`); :class:`femkit.fem.PoissonProblem` calls these for ``element="P2"``.
Cells are straight-sided (affine): a curved boundary is represented by its chords, so P2 on a
polygonal approximation of a curved domain keeps the geometric error O(h^2) (the rates 3 and 2
hold on polygonal domains).

- load ``F_i = int f phi_i`` by a rule exact for P2 products (degree 4: ``gauss6`` on triangles,
  ``sym14`` on tetrahedra, :func:`load_rule`); a constant ``f``
  exactly (``f |T| int phi_i / |T|``);
- Neumann ``int_facet h phi_i ds`` with the facet's P2 trace (3 dofs per edge, 6 per face) by a
  degree-5 Gauss rule on edges and ``gauss6`` on faces;
- Dirichlet data interpolated at the vertices and the edge midpoints of the tagged facets;
- errors ``||u - u_h||`` and ``||grad(u - u_h)||`` by a rule of degree ``order`` with the P2
  field evaluated at its points.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> element_load(m, 6.0, "P2").round(12).tolist()      # 6 * |T| * (0, 0, 0, 1/3, 1/3, 1/3)
[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..elements import Element, get_element
from ..errors import InputError
from ._elements import cell_measures, select_elements, simplex_gradients
from .coefficients import evaluate_callable
from .dofs import DofMap, dof_map
from .quadrature import blocks, get_rule, rule_for_degree
from . import sparsity

__all__ = ["element_load", "element_neumann", "boundary_dofs", "dof_weights", "element_error_norms",
           "element_energy_error", "evaluate"]

#: Gauss-Legendre, 3 points on [0, 1] (degree 5): the P2 Neumann rule on edges.
_G3 = np.array([0.5 - 0.5 * np.sqrt(0.6), 0.5, 0.5 + 0.5 * np.sqrt(0.6)])
_W3 = np.array([5.0, 8.0, 5.0]) / 18.0


def dof_weights(mesh, element="P2", *, elements=None) -> np.ndarray:
    """``w_i = int phi_i dx`` (n_dofs,) over the cells ``elements`` (None: all, and then
    ``sum w = |Omega|``; P2 vertex weights are 0 on triangles and negative on tetrahedra)."""
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    idx = select_elements(mesh, elements)
    vol, _ = cell_measures(mesh, idx)
    rule = rule_for_degree(elem.degree, mesh.dim)
    ref = rule.weights @ elem.basis(rule.points)                     # (n,) int phi / |T|
    cells = dofs.cells if idx is None else dofs.cells[idx]
    return np.bincount(cells.ravel(), weights=np.outer(vol, ref).ravel(), minlength=dofs.n_dofs)


def load_rule(element: Element):
    """The default load rule of ``element``: the cheapest registered rule exact for its products
    (degree :attr:`~femkit.elements.base.Element.load_degree`; P2: ``gauss6``, tetrahedra ``sym14``)."""
    return rule_for_degree(element.load_degree, element.dim, every=True)


def element_load(mesh, f, element="P2", *, rule: str | None = None, elements=None) -> np.ndarray:
    """Load vector ``int f phi_i`` (n_dofs,) of ``element`` over the cells ``elements`` (None:
    all; a distributed run's own cells); ``rule`` a quadrature rule name (default: the cheapest
    registered rule of degree :attr:`Element.load_degree`)."""
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    idx = select_elements(mesh, elements)
    quad = get_rule(rule, mesh.dim) if rule else load_rule(elem)
    phi = elem.basis(quad.points)                                    # (q, n)
    if callable(f) and idx is None and sparsity.compiled_from(mesh.n_cells, elem):  # the assembly's threshold
        F = _load_compiled(mesh, dofs, f, quad, phi)
        if F is not None:
            return F
    vol, cells = cell_measures(mesh, idx)
    if not callable(f):
        from .load import _scalar

        local = np.outer(vol * _scalar(f), quad.weights @ phi)
    else:
        from .load import _source_values

        fq = _source_values(mesh, f, quad, cells, idx)               # (m, q)
        local = ((fq * quad.weights) @ phi) * vol[:, None]
    cells = dofs.cells if idx is None else dofs.cells[idx]
    return np.bincount(cells.ravel(), weights=local.ravel(), minlength=dofs.n_dofs)


def _load_compiled(mesh, dofs: DofMap, f, quad, phi: np.ndarray) -> np.ndarray | None:
    """:func:`element_load` of a callable ``f`` by the compiled passes
    (:mod:`femkit.fem._element_kernels`), block by block of :func:`~femkit.fem.quadrature.blocks`
    (the rule's points' coordinates, ``f`` on them, then measures, products and sums: the block's
    arrays stay in cache, none is ever the whole mesh's); None when ``f`` is not finite somewhere
    or a cell is degenerate (the NumPy path then raises naming them)."""
    from ._element_kernels import element_load_kernel, quadrature_coordinates
    from .fused import source_values

    wphi = quad.weights[:, None] * phi
    F = np.zeros(dofs.n_dofs)
    fq = source_values(mesh, f, quad)
    if fq is not None:
        ok = bool(np.isfinite(fq).all()) and element_load_kernel(dofs.cells, mesh.points, fq, wphi, F)
        return F if ok else None
    for part in blocks(mesh.n_cells):
        cells = dofs.cells[part]
        fq = evaluate_callable(f, *quadrature_coordinates(cells, mesh.points, quad.points), name="f")
        if not (np.isfinite(fq).all() and element_load_kernel(cells, mesh.points, fq, wphi, F)):
            return None
    return F


def _facet_dofs(mesh, dofs: DofMap, facets: np.ndarray) -> np.ndarray:
    """(k, 3) or (k, 6) dofs of boundary facets: their vertices, then their edges in the order of
    the facet's P2 basis ((0,1) on an edge; (0,1), (1,2), (0,2) on a face)."""
    from ..mesh.edges import edge_ids

    if not len(dofs.edge_nodes):
        return facets
    pairs = [[0, 1]] if mesh.dim == 2 else get_element("P2", 2).local_edges.tolist()
    ids = [edge_ids(mesh, dofs.edge_nodes, facets[:, p]) for p in pairs]
    return np.column_stack([facets] + [dofs.n_vertices + i for i in ids])


def _segment_p2(s: np.ndarray) -> np.ndarray:
    l0, l1 = 1.0 - s, s
    return np.column_stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), 4 * l0 * l1])


def element_neumann(mesh, tags, h, element="P2") -> np.ndarray:
    """``int h phi_i ds`` (n_dofs,) over the boundary facets with ``tags`` (None: the whole
    boundary; as :func:`femkit.fem.neumann.assemble_neumann`)."""
    from .neumann import _flux_value, tagged_facets

    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    facets = np.asarray(tagged_facets(mesh, tags), dtype=np.int64)
    p = mesh.points[facets]                                          # (k, d, d)
    if mesh.dim == 2:
        size = np.hypot(*(p[:, 1] - p[:, 0]).T)
        bary = np.column_stack([1.0 - _G3, _G3])
        weights, phi = _W3, _segment_p2(_G3)
        if elem.degree == 1:
            phi = bary
    else:
        size = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
        rule = get_rule("gauss6")
        bary, weights = rule.points, rule.weights
        phi = get_element(elem.name, 2).basis(bary)
    if callable(h):
        coords = np.einsum("qa,kad->dkq", bary, p)
        hq = evaluate_callable(h, *coords, name="h")                 # (k, q)
        local = size[:, None] * ((hq * weights) @ phi)
    else:
        local = np.outer(_flux_value(h) * size, weights @ phi)
    if not np.isfinite(local).all():
        raise InputError("Neumann flux is not finite on some boundary facets")
    fdofs = _facet_dofs(mesh, dofs, facets)
    return np.bincount(fdofs.ravel(), weights=local.ravel(), minlength=dofs.n_dofs)


def boundary_dofs(mesh, dofs: DofMap, tags) -> np.ndarray:
    """Sorted dofs on the boundary facets with ``tags`` (None: the whole boundary): their
    vertices and, for P2, their edges (tags checked as :func:`femkit.mesh.boundary_nodes`)."""
    from ..mesh.edges import boundary_nodes
    from .neumann import tagged_facets

    nodes = boundary_nodes(mesh, tags)
    if not len(dofs.edge_nodes):
        return nodes
    facets = np.asarray(tagged_facets(mesh, tags), dtype=np.int64)
    return np.unique(np.concatenate([nodes, _facet_dofs(mesh, dofs, facets)[:, mesh.dim:].ravel()]))


def evaluate(mesh, u: np.ndarray, points: np.ndarray, element="P2", elements=None):
    """Values (k, q) and gradients (k, q, d) of the finite-element function ``u`` at the
    barycentric ``points`` (q, d + 1) of the cells ``elements`` (None: all)."""
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    grads, vol, _ = simplex_gradients(mesh, elements)
    cells = dofs.cells if elements is None else dofs.cells[elements]
    ue = np.asarray(u)[cells]                                        # (k, n)
    val = ue @ elem.basis(points).T                                  # (k, q)
    dl = np.einsum("kn,qna->kqa", ue, elem.lambda_gradients(points))  # d u / d lambda
    return val, np.einsum("kqa,kad->kqd", dl, grads), vol


def element_energy_error(mesh, u: np.ndarray, grad_exact: Callable, kappa=1.0, *, element="P2",
                         order: int = 5) -> float:
    """``(int kappa |grad(u - u_h)|^2)^(1/2)`` of the finite-element function ``u`` (``kappa``
    per cell, as the assembly takes it); :func:`femkit.fem.norms.energy_error` for P1."""
    from .coefficients import element_coefficient

    return _squares(mesh, u, None, grad_exact, element, order, element_coefficient(mesh, kappa))[1] ** 0.5


def element_error_norms(mesh, u: np.ndarray, exact: Callable, grad_exact: Callable | None = None, *,
                        element="P2", order: int = 5, elements=None, squared: bool = False) -> dict:
    """``L2``, ``H1_semi`` (None without ``grad_exact``) and ``max_nodal`` (over every dof:
    vertices and edge midpoints) errors of the finite-element function ``u`` (n_dofs,), as
    :func:`femkit.fem.norms.error_norms` for P1; the rule is exact to degree ``order``.

    ``elements``: over these cells only (their dofs for ``max_nodal``; ``u`` is read there
    only), ``squared``: the integrals not square-rooted -- what a distributed run sums over
    ranks (as :func:`~femkit.fem.norms.error_norms` takes them)."""
    idx = select_elements(mesh, elements)
    l2, h1 = _squares(mesh, u, exact, grad_exact, element, order, None, idx)
    dofs = dof_map(mesh, element)
    at = np.arange(dofs.n_dofs) if idx is None else np.unique(dofs.cells[idx])
    nodal = np.asarray(u)[at] - evaluate_callable(exact, *dofs.points(mesh)[at].T, name="exact")
    root = (lambda v: v) if squared else np.sqrt
    out = {"L2": float(root(l2)), "H1_semi": None if grad_exact is None else float(root(h1)),
           "max_nodal": float(np.abs(nodal).max()) if nodal.size else 0.0}
    for k, v in out.items():
        if v is not None and not np.isfinite(v):
            raise InputError(f"error norm {k} is not finite (exact solution or u not finite)")
    return out


def _squares(mesh, u, exact, grad_exact, element, order: int, weight, cells=None) -> tuple[float, float]:
    """``(int (u - u_h)^2, int w |grad(u - u_h)|^2)`` block by block over ``cells`` (None: all;
    ``exact`` None: 0; ``weight`` None: 1, else one value per cell)."""
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    u = np.asarray(u, dtype=np.float64)
    if u.shape != (dofs.n_dofs,):
        raise InputError(f"u must have one value per {elem.name} dof, shape ({dofs.n_dofs},), got {u.shape}")
    rule = rule_for_degree(order, mesh.dim)
    l2 = h1 = 0.0
    every = np.arange(mesh.n_cells) if cells is None else np.asarray(cells, dtype=np.int64)
    for part in blocks(len(every)):
        idx = every[part]
        val, grad, vol = evaluate(mesh, u, rule.points, elem, idx)
        coords = rule.physical_points(mesh, mesh.cells[idx])
        if exact is not None:
            diff = val - evaluate_callable(exact, *coords, name="exact")
            l2 += float(vol @ ((diff * diff) @ rule.weights))
        if grad_exact is not None:
            g = grad_exact(*coords)
            try:
                sq = sum((grad[:, :, d] - np.broadcast_to(np.asarray(g[d], dtype=np.float64), val.shape)) ** 2
                         for d in range(mesh.dim))
            except (TypeError, IndexError, ValueError) as exc:
                raise InputError(f"grad_exact must return {mesh.dim} components: {exc}") from None
            w = vol if weight is None else vol * weight[idx]
            h1 += float(w @ (sq @ rule.weights))
    return l2, h1
