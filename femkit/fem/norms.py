"""Errors of a P1 solution against an exact solution.

``L2 = ||u - u_h||``, ``H1_semi = ||grad(u - u_h)||`` (needs ``grad_exact``), both by a
quadrature rule of degree ``order`` per element (default 5: Dunavant 7 points, so the
quadrature error is far below the discretisation error), and ``max_nodal = max_i |u(x_i) - u_i|``.
Callables that bring compiled kernels (:mod:`femkit.fem.fused`: a case file's expressions on a
large mesh) are integrated in one compiled pass over the points, the others by NumPy block by
block.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> e = error_norms(m, np.array([0., 1., 0.]), lambda x, y: x, lambda x, y: (1 + 0 * x, 0 * y))
>>> [round(e[k], 14) for k in ("L2", "H1_semi", "max_nodal")]
[0.0, 0.0, 0.0]
"""

from __future__ import annotations

import weakref
from typing import Callable

import numpy as np

from ..errors import InputError
from ._elements import p1_gradients, select_elements, simplex_gradients, triangle_geometry
from .coefficients import evaluate_callable
from .fused import error_sums, kernels_for, nodal_error
from .quadrature import blocks, rule_for_degree


def error_norms(mesh, u: np.ndarray, exact: Callable, grad_exact: Callable | None = None, *,
                order: int = 5, elements=None, squared: bool = False) -> dict:
    """L2, H1-seminorm and max nodal errors of the P1 function ``u`` against ``exact``.

    Parameters
    ----------
    mesh : Mesh
    u : ndarray, shape (n,)
        Nodal values.
    exact : callable exact(x, y) (exact(x, y, z) on tetrahedra)
    grad_exact : callable returning ``(du/dx, du/dy)`` (``(du/dx, du/dy, du/dz)``), optional
        Without it ``H1_semi`` is ``None``.
    order : int
        Polynomial degree the quadrature must integrate exactly (a rule of at least this degree).
    elements : index array or boolean mask, optional
        Integrate over these elements only and take ``max_nodal`` over their nodes (a
        partition: only the values of ``u`` at those nodes are read).
    squared : bool
        Return ``L2`` and ``H1_semi`` squared (integrals that sum over a partition of the
        elements, as a distributed run reduces them).

    Returns
    -------
    dict with keys ``L2``, ``H1_semi`` (float or None), ``max_nodal``.

    Raises
    ------
    InputError
        ``u`` of the wrong length, no registered rule of degree ``order``, non-finite norms.
    """
    u = np.asarray(u, dtype=np.float64)
    if u.shape != (mesh.n_points,):
        raise InputError(f"u must have one value per node, shape ({mesh.n_points},), got {u.shape}")
    rule = rule_for_degree(order, mesh.dim)
    root = (lambda v: v) if squared else np.sqrt
    idx = select_elements(mesh, elements)
    kernels = None if idx is not None else kernels_for(mesh, exact=exact, grad_exact=grad_exact)
    sums = None if kernels is None else error_sums(mesh, u, rule, kernels)
    if sums is not None:  # every point visited once for every integral, compiled
        l2_sq, h1_sq = sums[0], (sums[1] if grad_exact is not None else None)
        tri = None
    else:
        l2_sq, h1_sq, tri = _error_sums(mesh, u, exact, grad_exact, rule, idx)
    l2 = float(root(np.sum(l2_sq)))
    big = None if kernels is None else nodal_error(mesh, u, exact)
    if big is None:
        nodes = slice(None) if elements is None else np.unique(tri)
        pts = mesh.points[nodes]
        nodal = u[nodes] - evaluate_callable(exact, *pts.T, name="exact")
        big = float(np.max(np.abs(nodal))) if nodal.size else 0.0
    out = {"L2": l2, "H1_semi": None, "max_nodal": big}
    if h1_sq is not None:
        out["H1_semi"] = float(root(np.sum(h1_sq)))
        if idx is None:
            _remember_gradient_error(mesh, u, grad_exact, rule, h1_sq)
    for k, v in out.items():
        if v is not None and not np.isfinite(v):
            raise InputError(f"error norm {k} is not finite (exact solution or u not finite)")
    return out


def _error_sums(mesh, u, exact, grad_exact, rule, idx):
    """Per element ``int (u - u_h)^2`` and ``int |grad(u - u_h)|^2`` (None without
    ``grad_exact``) by NumPy, block by block, and the elements' vertices."""
    geometry = triangle_geometry(mesh, idx) if mesh.dim == 2 else simplex_gradients(mesh, idx)
    tri = geometry[-1]
    l2_sq = np.empty(len(tri))
    h1_sq = None if grad_exact is None else np.empty(len(tri))
    for s in blocks(len(tri)):  # the exact solution and its gradient once per point, per block
        part = tuple(a[s] for a in geometry)
        xy = rule.physical_points(mesh, part[-1])
        diff = u[part[-1]] @ rule.points.T - evaluate_callable(exact, *xy, name="exact")
        l2_sq[s] = part[1] * ((diff * diff) @ rule.weights)
        if h1_sq is not None:
            h1_sq[s] = _gradient_error_sq(mesh, u, grad_exact, rule, part, xy)
    return l2_sq, h1_sq, tri


#: The last per-element ``int_T |grad(u - u_h)|^2`` of each mesh (weakly keyed, so it goes with
#: the mesh): :func:`energy_error` after :func:`error_norms` of the same ``u``, exact gradient
#: and rule reuses it instead of evaluating the gradient at every quadrature point again.
_GRADIENT_ERROR: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _remember_gradient_error(mesh, u, grad_exact, rule, sq) -> None:
    try:
        _GRADIENT_ERROR[mesh] = (u.copy(), grad_exact, rule.name, sq)
    except TypeError:  # a mesh-like object that cannot be weakly referenced: nothing kept
        pass


def _gradient_error_all(mesh, u, grad_exact, rule) -> np.ndarray:
    """Per element ``int_T |grad u - grad u_h|^2`` over the whole mesh (block by block), or the
    one :func:`error_norms` just computed for the same ``u``, ``grad_exact`` and ``rule``."""
    try:
        hit = _GRADIENT_ERROR.pop(mesh, None)  # used once: not kept past its stage
    except TypeError:
        hit = None
    if hit is not None and hit[1] is grad_exact and hit[2] == rule.name and np.array_equal(hit[0], u):
        return hit[3]
    kernels = kernels_for(mesh, grad_exact=grad_exact)
    sums = None if kernels is None else error_sums(mesh, u, rule, kernels)
    if sums is not None:
        return sums[1]
    geometry = triangle_geometry(mesh, None) if mesh.dim == 2 else simplex_gradients(mesh, None)
    sq = np.empty(len(geometry[-1]))
    for s in blocks(len(sq)):
        sq[s] = _gradient_error_sq(mesh, u, grad_exact, rule, tuple(a[s] for a in geometry))
    return sq


def _gradient_error_sq(mesh, u, grad_exact, rule, geometry=None, xy=None) -> np.ndarray:
    """Per element ``int_T |grad u - grad u_h|^2`` by the quadrature ``rule``."""
    if mesh.dim == 3:
        return _gradient_error_sq_3d(mesh, u, grad_exact, rule, geometry, xy)
    e, area, signed, tri = triangle_geometry(mesh, None) if geometry is None else geometry
    x, y = rule.physical_points(mesh, tri) if xy is None else xy
    g_h = p1_gradients(e, signed, u[tri])
    g = grad_exact(x, y)
    try:
        gxe = np.broadcast_to(np.asarray(g[0], dtype=np.float64), x.shape)
        gye = np.broadcast_to(np.asarray(g[1], dtype=np.float64), x.shape)
    except (TypeError, IndexError, ValueError) as exc:
        raise InputError(f"grad_exact(x, y) must return (du/dx, du/dy): {exc}") from None
    dx, dy = g_h[:, 0, None] - gxe, g_h[:, 1, None] - gye
    return area * ((dx * dx + dy * dy) @ rule.weights)


def _gradient_error_sq_3d(mesh, u, grad_exact, rule, geometry, xyz) -> np.ndarray:
    grads, volume, tets = simplex_gradients(mesh, None) if geometry is None else geometry
    xyz = rule.physical_points(mesh, tets) if xyz is None else xyz
    g_h = np.einsum("ma,mad->md", u[tets], grads)
    g = grad_exact(*xyz)
    try:
        ge = [np.broadcast_to(np.asarray(g[d], dtype=np.float64), xyz[0].shape) for d in range(3)]
    except (TypeError, IndexError, ValueError) as exc:
        raise InputError(f"grad_exact(x, y, z) must return (du/dx, du/dy, du/dz): {exc}") from None
    sq = sum((g_h[:, d, None] - ge[d]) ** 2 for d in range(3))
    return volume * (sq @ rule.weights)


def energy_error(mesh, u: np.ndarray, grad_exact: Callable, kappa=1.0, *, order: int = 5,
                 per_element: bool = False):
    """Energy-norm error ``(int kappa |grad(u - u_h)|^2)^(1/2)`` of the P1 function ``u``.

    ``kappa`` as in :func:`~femkit.fem.coefficients.element_coefficient` (barycentre values, as
    the stiffness assembly uses); with ``kappa = 1`` it is the H1 seminorm of
    :func:`error_norms`. ``per_element=True`` returns the (m,) element contributions
    ``(int_T kappa |grad e|^2)^(1/2)`` instead of the global number.

    >>> import numpy as np
    >>> from femkit.mesh import Mesh
    >>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
    >>> energy_error(m, np.zeros(3), lambda x, y: (1 + 0 * x, 0 * y), kappa=4.0)   # sqrt(4 * 1/2)
    1.4142135623730951
    """
    from .coefficients import element_coefficient

    u = np.asarray(u, dtype=np.float64)
    if u.shape != (mesh.n_points,):
        raise InputError(f"u must have one value per node, shape ({mesh.n_points},), got {u.shape}")
    sq = element_coefficient(mesh, kappa) * _gradient_error_all(mesh, u, grad_exact,
                                                                rule_for_degree(order, mesh.dim))
    if not np.isfinite(sq).all():
        raise InputError("energy error is not finite (exact gradient or u not finite)")
    return np.sqrt(sq) if per_element else float(np.sqrt(sq.sum()))
