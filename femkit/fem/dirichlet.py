"""Dirichlet conditions ``u = g`` by elimination with lifting.

With ``free`` / ``fixed`` node sets, the reduced system is
``A = K[free, free]``, ``b = F[free] - K[free, fixed] g``; ``A`` stays symmetric positive
definite (a principal submatrix of K) so CG applies.

>>> import numpy as np
>>> import scipy.sparse as sp
>>> K = sp.csr_matrix(np.array([[2., -1, 0], [-1, 2, -1], [0, -1, 2]]))
>>> sys = apply_dirichlet(K, np.zeros(3), [0, 2], [1.0, 3.0])
>>> sys.A.toarray().tolist(), sys.b.tolist()
([[2.0]], [4.0])
>>> sys.expand(np.array([2.0])).tolist()
[1.0, 2.0, 3.0]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Union

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from .coefficients import evaluate_callable
from ..warmup_registry import register_kernels, register_threshold

Values = Union[float, np.ndarray, Callable]


@dataclass
class DirichletSystem:
    """Reduced system after eliminating Dirichlet nodes.

    Attributes
    ----------
    A : csr_matrix
        ``K[free][:, free]`` (symmetric positive definite for a Poisson problem).
    b : ndarray
        ``F[free] - K[free][:, fixed] @ g``.
    free, fixed : ndarray of int
        Sorted node indices.
    values : ndarray
        ``g`` at ``fixed``.
    n : int
        Number of nodes of the full system.
    """

    A: sp.csr_matrix
    b: np.ndarray
    free: np.ndarray
    fixed: np.ndarray
    values: np.ndarray
    n: int

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Full nodal vector: ``u_free`` on free nodes, ``g`` on fixed nodes."""
        u_free = np.asarray(u_free, dtype=np.float64)
        if u_free.shape != (len(self.free),):
            raise InputError(f"expected {len(self.free)} free values, got shape {u_free.shape}")
        u = np.empty(self.n)
        u[self.free] = u_free
        u[self.fixed] = self.values
        return u


def dirichlet_values(mesh, nodes, g: Values) -> np.ndarray:
    """Values of ``g`` (scalar, per-node array, or callable ``g(x, y)``; ``g(x, y, z)`` in 3D)
    at ``nodes``."""
    nodes = np.asarray(nodes, dtype=np.int64).ravel()
    if callable(g):
        pts = mesh.points[nodes]
        vals = np.array(evaluate_callable(g, *pts.T, name="g"))
    else:
        vals = np.asarray(g, dtype=np.float64)
        if vals.ndim == 0:
            vals = np.full(len(nodes), float(vals))
        elif vals.shape != (len(nodes),):
            raise InputError(f"Dirichlet values must be a scalar or have shape ({len(nodes)},), got {vals.shape}")
    if not np.isfinite(vals).all():
        bad = nodes[~np.isfinite(vals)]
        raise InputError(f"Dirichlet values are not finite at {len(bad)} node(s), first {bad[:10].tolist()}")
    return vals


#: Systems with at least this many rows are reduced by one compiled pass over ``K``
#: (:func:`femkit.fem._kernels.eliminate_kernel`: the same ``A`` and ``b`` as SciPy's indexing).
NUMBA_THRESHOLD = 100_000
register_threshold(__name__, "NUMBA_THRESHOLD")
register_kernels("P1 assembly", "femkit.fem._kernels", "_eliminate", rank=1)


def apply_dirichlet(K, F, nodes, values, *, overwrite: bool = False) -> DirichletSystem:
    """Eliminate the Dirichlet nodes from ``K u = F``.

    Parameters
    ----------
    K : sparse matrix, shape (n, n)
    F : ndarray, shape (n,)
    nodes : array of int, or boolean mask of shape (n,)
        Dirichlet nodes (duplicates allowed if their values agree).
    values : float or array of len(nodes) (of ``mask.sum()`` for a mask)
        ``g`` at ``nodes`` (use :func:`dirichlet_values` for a callable); must be finite.
    overwrite : bool
        Let ``A`` take over ``K``'s arrays (elimination in place, no second matrix in memory);
        ``K`` must not be used afterwards. Only for a CSR ``K`` of float64 with sorted indices
        from :data:`NUMBA_THRESHOLD` rows on; otherwise ignored.

    Returns
    -------
    DirichletSystem

    Raises
    ------
    InputError
        Shapes that do not match, node ids out of range or not integers, non-finite values,
        a node given twice with different values.
    """
    given = K
    K = sp.csr_matrix(K)
    n = K.shape[0]
    F = np.asarray(F, dtype=np.float64)
    if K.shape != (n, n) or F.shape != (n,):
        raise InputError(f"K must be square and F of matching length, got {K.shape} and {F.shape}")
    nodes = _node_ids(nodes, n)
    vals = np.asarray(values, dtype=np.float64)
    vals = np.full(len(nodes), float(vals)) if vals.ndim == 0 else vals.ravel()
    if vals.shape != nodes.shape:
        raise InputError(f"{len(nodes)} Dirichlet nodes but {vals.size} values")
    if not np.isfinite(vals).all():
        bad = nodes[~np.isfinite(vals)]
        raise InputError(f"Dirichlet values are not finite at {len(bad)} node(s), "
                         f"first {bad[:10].tolist()}")
    fixed, first, inverse = np.unique(nodes, return_index=True, return_inverse=True)
    g = vals[first]
    clash = np.flatnonzero(vals != g[inverse])
    if clash.size:
        i = clash[0]
        raise InputError(f"Dirichlet node {int(nodes[i])} is given twice with different values "
                         f"({g[inverse[i]]:g} and {vals[i]:g}); {clash.size} such entries")
    is_fixed = np.zeros(n, dtype=bool)
    is_fixed[fixed] = True
    free = np.flatnonzero(~is_fixed)
    if n >= NUMBA_THRESHOLD and K.has_sorted_indices and K.dtype == np.float64:
        from ._kernels import eliminate_kernel

        g_full = np.zeros(n)
        g_full[fixed] = g
        # in place only on the caller's own CSR arrays (sp.csr_matrix(K) shares them)
        in_place = overwrite and sp.issparse(given) and given.format == "csr"
        A, b = eliminate_kernel(K, F, is_fixed, g_full, in_place)
        return DirichletSystem(A=A, b=b, free=free, fixed=fixed, values=g, n=n)
    K_free = K[free]
    A = K_free[:, free].tocsr()
    A.sort_indices()
    g_full = np.zeros(n)
    g_full[fixed] = g
    b = F[free] - K_free @ g_full
    return DirichletSystem(A=A, b=b, free=free, fixed=fixed, values=g, n=n)


def _node_ids(nodes, n: int) -> np.ndarray:
    """Node ids from an integer array or a boolean mask of length ``n``; range checked."""
    arr = np.asarray(nodes)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise InputError(f"a boolean Dirichlet node mask must have shape ({n},), got {arr.shape}")
        return np.flatnonzero(arr)
    arr = arr.ravel()
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        try:
            ints = arr.astype(np.int64)
            exact = bool(np.all(ints == arr))
        except (TypeError, ValueError):
            exact = False
        if not exact:
            raise InputError(f"Dirichlet nodes must be integer node ids (or a boolean mask), "
                             f"got {arr.dtype} values such as {arr[:3].tolist()}")
        arr = ints
    arr = arr.astype(np.int64)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise InputError(f"Dirichlet node indices out of range 0..{n - 1}")
    return arr
