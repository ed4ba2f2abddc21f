"""Rest data and deformation gradients of P1 triangles (plane strain) and tetrahedra.

For an element with rest vertices ``X_0 .. X_d`` the rest edge matrix is
``Dm = [X_1 - X_0, ..., X_d - X_0]`` (``d x d``) and the deformed one ``Ds`` likewise from the
current positions; the deformation gradient is constant per element, ``F = Ds Dm^-1``
(Sifakis & Barbic, "FEM simulation of 3D deformable solids", SIGGRAPH course 2012). Written as
``F = sum_n x_n (x) g_n`` with the shape-function gradients ``g_n`` (rows of
:attr:`RestShape.gradients`, ``g_0 = -sum_{n>0} g_n``), so ``dF_ab / dx_{n,a} = g_{n,b}``: the
element force is ``-vol * P g_n`` and the Hessian ``vol * g^T (dP/dF) g``.

The invertible SVD (Irving, Teran & Fedkiw 2004) ``F = U diag(s) V^T`` takes
``det U = det V = +1``; an inverted element (``det F < 0``) then has exactly one negative
stretch, the one of smallest magnitude.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DegenerateMeshError, InputError

__all__ = ["RestShape", "rest_shape", "deformation_gradients", "invertible_svd"]


@dataclass(frozen=True, eq=False)
class RestShape:
    """Per-element rest data, computed once per mesh.

    Attributes
    ----------
    cells : (m, d+1) int64 vertex indices (P2: ``(m, 6 | 10)`` node indices, vertices then
        edge midpoints, :mod:`femkit.solids.quadratic`).
    dm_inv : (m, d, d) inverse rest edge matrices ``Dm^-1``.
    volumes : (m,) rest volumes (areas in 2D; plane strain per unit thickness).
    gradients : (m, d+1, d) shape-function gradients ``g_n`` (``F = sum_n x_n g_n^T``); P2:
        ``(m q, nv, d)``, at the ``q`` quadrature points of each cell (row ``e q + k``).
    weights : (m q,) quadrature weight times cell volume (P2), or None (P1: one point, the
        volumes).
    n_points : ``q``, quadrature points per cell (1 for P1).
    element : the element's name, ``"P1"`` or ``"P2"``.
    n_nodes : number of nodes (P2: vertices + edges), or None (P1: the points).
    """

    cells: np.ndarray
    dm_inv: np.ndarray
    volumes: np.ndarray
    gradients: np.ndarray
    weights: np.ndarray | None = None
    n_points: int = 1
    element: str = "P1"
    n_nodes: int | None = None

    @property
    def dim(self) -> int:
        return int(self.dm_inv.shape[1])

    @property
    def n_cells(self) -> int:
        return int(self.cells.shape[0])


def _check_arrays(points, cells) -> tuple[np.ndarray, np.ndarray]:
    X = np.ascontiguousarray(points, dtype=float)
    T = np.asarray(cells)
    if X.ndim != 2 or X.shape[1] not in (2, 3):
        raise InputError(f"rest positions must have shape (n, 2) or (n, 3), got {X.shape}")
    d = X.shape[1]
    if T.ndim != 2 or T.shape[1] != d + 1 or not np.issubdtype(T.dtype, np.integer):
        raise InputError(f"cells must be an (m, {d + 1}) integer array for {d}D points, got "
                         f"shape {T.shape}, dtype {T.dtype}")
    if T.size and (T.min() < 0 or T.max() >= len(X)):
        raise InputError(f"cell vertex indices must lie in [0, {len(X) - 1}]")
    if not np.all(np.isfinite(X)):
        raise InputError("rest positions must be finite")
    return X, np.ascontiguousarray(T, dtype=np.int64)


def rest_shape(points, cells, *, rel_tol: float = 1e-12) -> RestShape:
    """Rest data of triangles (2D points) or tetrahedra (3D points).

    Raises
    ------
    DegenerateMeshError
        An element with zero (below ``rel_tol`` times the mean ``|det Dm|``) or negative rest
        volume (inverted input); ``element_ids`` lists them and the message names the first.

    >>> r = rest_shape([[0., 0.], [1., 0.], [0., 1.]], [[0, 1, 2]])
    >>> float(r.volumes[0]), r.gradients[0].tolist()
    (0.5, [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    """
    X, T = _check_arrays(points, cells)
    d = X.shape[1]
    Dm = (X[T[:, 1:]] - X[T[:, :1]]).transpose(0, 2, 1)       # columns X_n - X_0
    det = np.linalg.det(Dm) if len(T) else np.zeros(0)
    scale = float(np.mean(np.abs(det))) if len(T) else 0.0
    bad = np.flatnonzero(det <= rel_tol * scale)
    if len(bad):
        kind = "inverted" if det[bad[0]] < -rel_tol * scale else "zero-volume"
        raise DegenerateMeshError(
            f"{len(bad)} {kind if len(bad) == 1 else 'inverted or zero-volume'} element(s) in the "
            f"rest mesh, first {int(bad[0])} (det Dm = {det[bad[0]]:.3e}; vertices must be "
            f"positively oriented)", bad[:20])
    dm_inv = np.linalg.inv(Dm)
    grads = np.empty((len(T), d + 1, d))
    grads[:, 1:, :] = dm_inv                                    # g_n = row n-1 of Dm^-1
    grads[:, 0, :] = -dm_inv.sum(axis=1)
    fact = 2.0 if d == 2 else 6.0
    return RestShape(T, np.ascontiguousarray(dm_inv), det / fact, np.ascontiguousarray(grads))


def deformation_gradients(x, rest: RestShape) -> np.ndarray:
    """``F = Ds Dm^-1`` of every element at positions ``x`` (``(n, d)``), shape ``(m, d, d)``;
    for P2 at every quadrature point, ``(m q, d, d)`` (row ``e q + k``)."""
    x = np.asarray(x, dtype=float)
    if rest.n_points == 1:
        return np.einsum("mna,mnb->mab", x[rest.cells], rest.gradients)
    q = rest.n_points
    g = rest.gradients.reshape(rest.n_cells, q, *rest.gradients.shape[1:])
    return np.einsum("mna,mqnb->mqab", x[rest.cells], g).reshape(-1, x.shape[1], x.shape[1])


def invertible_svd(F) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``F = U diag(s) V^T`` with ``det U = det V = 1`` (Irving, Teran & Fedkiw 2004).

    ``F``: ``(..., d, d)``. Returns ``U, s, V`` with ``s`` sorted by decreasing magnitude and,
    where ``det F < 0``, the last (smallest) stretch negative.

    >>> U, s, V = invertible_svd(np.diag([2.0, 1.0, -0.5]))
    >>> s.tolist()
    [2.0, 1.0, -0.5]
    """
    F = np.asarray(F, dtype=float)
    U, s, Vt = np.linalg.svd(F)
    V = np.swapaxes(Vt, -1, -2).copy()
    s = s.copy()
    for M in (U, V):
        neg = np.linalg.det(M) < 0.0
        M[neg, ..., -1] *= -1.0
        s[neg, ..., -1] *= -1.0
    return U, s, V
