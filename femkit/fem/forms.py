"""Element-generic assembly of stiffness and mass matrices on affine simplices (P1, P2, ...).

On a straight-sided cell ``T`` the barycentric gradients ``G = grad lambda`` (d + 1, d) are
constant, so with ``D_i = dphi_i / dlambda`` (:meth:`femkit.elements.base.Element.lambda_gradients`)

    ``K^T_ij = kappa_T |T| sum_ab (G G^T)_ab S_abij``,  ``S_abij = (1/|T|) int_T D_ia D_jb``

and ``M^T_ij = rho_T |T| R_ij`` with ``R_ij = (1/|T|) int_T phi_i phi_j``. The reference tables
``S`` and ``R`` are integrated once per element by a rule exact for their degree
(:func:`femkit.fem.quadrature.rule_for_degree`), so each cell costs one small matrix product:
the local matrices of a block of cells are ``(m, (d+1)^2) @ ((d+1)^2, n^2)``. They go into the
CSR pattern of the dof map (:func:`femkit.fem.sparsity.pattern_for`) by ``np.bincount``, or,
from :data:`~femkit.fem.sparsity.NUMBA_THRESHOLD` cells on, block by block through one compiled
scatter (:func:`femkit.fem._kernels.scatter_kernel`), so no (m, n^2) array is ever whole; the
whole mesh's stiffness there is one compiled pass (geometry, local matrix, scatter:
:func:`femkit.fem._kernels.element_stiffness_kernel`). A P2 stiffness on a large mesh whose
pattern is not cached yet (a run's one assembly) is built with its pattern in one pass and
caches none (:func:`femkit.fem._element_kernels.first_stiffness`); a later matrix of that mesh
builds and caches the pattern then.

Coefficients (``kappa``, ``rho``) are constant per cell, as in the P1 assembly: a float, one
value per cell, a ``{tag or name: value}`` table or a callable evaluated at the cell centroids
(:func:`femkit.fem.coefficients.element_coefficient`).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> K = assemble_matrix(m, "stiffness", element="P2")
>>> K.shape, round(float(abs(K @ np.ones(6)).max()), 12)
((6, 6), 0.0)
>>> round(float(assemble_matrix(m, "mass", element="P2").sum()), 12)
0.5
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ..elements import Element, get_element
from ..errors import InputError
from ._elements import cell_measures, select_elements, simplex_gradients
from .coefficients import element_coefficient
from .dofs import dof_map
from .quadrature import blocks, rule_for_degree
from . import sparsity

__all__ = ["reference_stiffness", "reference_mass", "local_matrices", "assemble_matrix", "FORMS"]

#: The bilinear forms :func:`assemble_matrix` knows.
FORMS = ("stiffness", "mass")


@lru_cache(maxsize=None)
def _stiffness_table(name: str, dim: int) -> np.ndarray:
    elem = get_element(name, dim)
    rule = rule_for_degree(max(elem.stiffness_degree, 1), dim)
    D = elem.lambda_gradients(rule.points)                        # (q, n, d+1)
    S = np.einsum("q,qia,qjb->abij", rule.weights, D, D)
    S.setflags(write=False)
    return S


@lru_cache(maxsize=None)
def _mass_table(name: str, dim: int) -> np.ndarray:
    elem = get_element(name, dim)
    rule = rule_for_degree(elem.mass_degree, dim)
    phi = elem.basis(rule.points)                                 # (q, n)
    R = np.einsum("q,qi,qj->ij", rule.weights, phi, phi)
    R.setflags(write=False)
    return R


def reference_stiffness(element: Element) -> np.ndarray:
    """``S`` (d+1, d+1, n, n): ``S_abij = (1/|T|) int_T dphi_i/dlambda_a dphi_j/dlambda_b``
    (read-only, computed once per element)."""
    return _stiffness_table(element.name, element.dim)


def reference_mass(element: Element) -> np.ndarray:
    """``R`` (n, n): ``R_ij = (1/|T|) int_T phi_i phi_j`` (read-only, computed once)."""
    return _mass_table(element.name, element.dim)


def local_matrices(mesh, form: str, coefficient=1.0, *, element="P1", elements=None) -> np.ndarray:
    """Local matrices (k, n, n) of ``form`` (``"stiffness"`` or ``"mass"``) on the selected
    cells, each scaled by the cell's ``coefficient`` (kappa or rho) and measure.

    Raises :class:`~femkit.errors.InputError` for an unknown form or a non-positive
    coefficient, :class:`~femkit.errors.DegenerateMeshError` for zero-measure cells.
    """
    elem = get_element(element, mesh.dim)
    idx = select_elements(mesh, elements)
    scale = element_coefficient(mesh, coefficient, idx)
    n = elem.n_dofs
    return _local(mesh, elem, form, scale, idx).reshape(-1, n, n)


def _local(mesh, elem: Element, form: str, scale: np.ndarray, idx) -> np.ndarray:
    """(k, n * n) local matrices of the cells ``idx`` (None: all) with per-cell ``scale``."""
    n = elem.n_dofs
    if form == "mass":
        vol, _ = cell_measures(mesh, idx)
        return (scale * vol)[:, None] * reference_mass(elem).reshape(1, n * n)
    if form != "stiffness":
        raise InputError(f"unknown form {form!r}; valid forms: {', '.join(FORMS)}")
    grads, vol, _ = simplex_gradients(mesh, idx)
    G = np.einsum("kad,kbd->kab", grads, grads).reshape(len(vol), -1)
    G *= (scale * vol)[:, None]
    return G @ reference_stiffness(elem).reshape(-1, n * n)


def assemble_matrix(mesh, form: str, coefficient=1.0, *, element="P1", elements=None) -> sp.csr_matrix:
    """Assemble the global matrix of ``form`` (``"stiffness"``: ``int kappa grad u . grad v``;
    ``"mass"``: ``int rho u v``) for ``element`` (a name or :class:`~femkit.elements.Element`).

    Parameters
    ----------
    mesh : Mesh
    form : {"stiffness", "mass"}
    coefficient : float, (m,) array, dict {tag or name: value} or callable
        ``kappa`` or ``rho``, constant per cell (callables at the centroids).
    element : str or Element
        ``"P1"`` or ``"P2"`` (:data:`femkit.elements.ELEMENTS`).
    elements : index array or boolean mask, optional
        Assemble only these cells (the result keeps the global shape and pattern).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_dofs, n_dofs)
        Symmetric, sorted indices, dofs numbered by :func:`femkit.fem.dofs.dof_map`.
    """
    if form not in FORMS:
        raise InputError(f"unknown form {form!r}; valid forms: {', '.join(FORMS)}")
    elem = get_element(element, mesh.dim)
    dofs = dof_map(mesh, elem)
    idx = select_elements(mesh, elements)
    scale = element_coefficient(mesh, coefficient, idx)
    count = mesh.n_cells if idx is None else len(idx)
    compiled = sparsity.compiled_from(count, elem)
    if (form == "stiffness" and idx is None and elem.name != "P1" and compiled
            and sparsity.cached_pattern(mesh, dofs) is None):
        from ._element_kernels import first_stiffness   # pattern and values in one pass, none cached

        K = first_stiffness(mesh, dofs, scale, reference_stiffness(elem))
        if K is not None:
            return K
    pattern = sparsity.pattern_for(mesh, dofs)
    if not compiled or pattern.slots.dtype != np.int32:
        return pattern.assemble(_local(mesh, elem, form, scale, idx), elements=idx)
    from ._kernels import element_stiffness_kernel, scatter_kernel

    if form == "stiffness" and idx is None:  # one compiled pass: geometry, local matrix, scatter
        n = elem.n_dofs
        if elem.name != "P1":  # the symmetric products, vectorised (P1 keeps its kernel's bits)
            from ._element_kernels import element_stiffness_kernel
        data = element_stiffness_kernel(mesh, scale, reference_stiffness(elem).reshape(-1, n * n), pattern)
        if data is not None:
            return pattern.matrix(data)

    cells = np.arange(mesh.n_cells) if idx is None else idx
    data = np.zeros(pattern.nnz)
    for part in blocks(count):
        rows = cells[part]
        scatter_kernel(data, pattern.slots, rows, _local(mesh, elem, form, scale[part], rows))
    return pattern.matrix(data)
