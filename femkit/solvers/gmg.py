"""Geometric multigrid on nested meshes: a symmetric V-cycle as the ``gmg`` preconditioner.

Levels come from a :class:`~femkit.mesh.hierarchy.MeshHierarchy` (uniform red refinement), whose
prolongation is exact P1 interpolation; restriction is its transpose. Coarse operators are
Galerkin products ``A_l = P_l^T A_{l+1} P_l`` (any ``kappa``, also high contrast: Trottenberg,
Oosterlee and Schüller, *Multigrid*, 2001, sec. 2.3 and 7.7), or given by the caller
(``coarse_operators=``, e.g. rediscretised). For a ``kappa`` constant on the coarse cells both are
the same matrix (the P1 spaces are nested and the element integrals exact).

The Galerkin product is one compiled pass per level (:func:`galerkin_product`): Gustavson's
row-wise sparse product (Gustavson, "Two fast algorithms for sparse matrices: multiplication and
permuted transposition", ACM TOMS 4(3), 1978) over the rows of ``P^T``, which is built by a
counting-sort transposition (:func:`transpose_csr`) for that pass only: the V-cycle restricts with
``P``'s own arrays read as CSC (``P.T``, no copy, the same sums in the same order). The
pass returns canonical CSR and the diagonal the smoother needs; it equals SciPy's
``P.T @ A @ P`` to round-off.

One application is a V(nu, nu)-cycle from a zero initial guess: ``nu`` forward SOR sweeps
(Gauss-Seidel over-relaxed by ``omega``, default 1.25) before the coarse correction, ``nu`` backward
sweeps after it (compiled numba kernels), a cached direct factorisation
(:func:`femkit.solvers.kept_factor.factorize_kept`, the kept-factor path the linear-solve
session uses too) on the coarsest level. Backward SOR is the ``A``-adjoint of
forward SOR, so the cycle is a symmetric positive definite operator ``M ~ A^-1`` and PCG applies (Briggs, Henson and McCormick, *A Multigrid Tutorial*,
2000; Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., sec. 13.4).

Without a hierarchy the factory raises :class:`~femkit.errors.HierarchyError` naming the algebraic
alternative, ``amg_rs``.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from ..errors import HierarchyError, InputError
from .core.checks import check_positive_diagonal, check_symmetric, dependency_boundary, explicit_csr
from .preconditioners.base import Preconditioner
from ..warmup_registry import register_kernels

register_kernels("geometric multigrid", "femkit.solvers._gmg_kernels", "_galerkin_rows", "transpose", "add_matvec",
                 "gs_forward_zero", "gs_sweeps", "residual", rank=3)

#: Over-relaxation of the smoothing sweeps. Measured V(2,2) energy-norm factors (asymptotic, 7
#: levels from gmsh meshes of h = 0.5): unit square 0.114 / 0.100 / 0.102, L-shape 0.170 / 0.133 /
#: 0.134 for omega = 1 / 1.2 / 1.25 (docs/methods.md). 1.25 is within 2 % of 1.2 at 7 levels and
#: its factor is also level-independent on the unit square (growth 0.047 from 3 to 7 levels
#: against 0.0503). Forward SOR before and backward SOR after the coarse correction keep the
#: cycle symmetric for any omega.
DEFAULT_OMEGA = 1.25

#: The one-line advice every missing-hierarchy error ends with.
ALTERNATIVE = ("use preconditioner 'amg_rs' (algebraic multigrid, no hierarchy needed) "
               "or give the mesh 'refine: k' with k >= 1")


def _hierarchy_error(what: str) -> HierarchyError:
    return HierarchyError(f"{what} needs a nested mesh hierarchy (hierarchy=MeshHierarchy..., "
                          f"from uniform refinement), none was given; {ALTERNATIVE}")


def _unsigned(index: np.ndarray) -> np.ndarray:
    """An index array viewed as unsigned (no copy): numba then skips the negative-index
    wrap-around test on every ``x[indices[t]]``, which made the sweeps 2x slower than SciPy's
    SpMV (and 2.5x slower than with this view). scipy's own dtype is kept (int32 below 2^31
    entries: half the memory traffic of int64)."""
    return index.view(np.uint32 if index.dtype == np.int32 else np.uint64)


def _kernel_index(index: np.ndarray) -> np.ndarray:
    """An index array for the setup kernels, which do arithmetic on indices: int32 viewed as
    uint32 (:func:`_unsigned`), anything else as int64 (numba types ``uint64 + int`` as a float)."""
    if index.dtype == np.int32:
        return index.view(np.uint32)
    return index.astype(np.int64, copy=False)


def _csr(indptr, indices, data, shape) -> sp.csr_matrix:
    """A ``csr_matrix`` from kernel output: uint32 indices back to int32, ``indptr`` (int64 from
    the kernels) in the indices' dtype as SciPy keeps them (int64 both if ``nnz`` needs it)."""
    if indices.dtype == np.uint32:
        indices = indices.view(np.int32)
    if indptr[-1] > np.iinfo(indices.dtype).max:
        indices = indices.astype(np.int64)
    return sp.csr_matrix((data, indices, indptr.astype(indices.dtype, copy=False)), shape=shape)


def _float_csr(M) -> sp.csr_matrix:
    """``M`` as CSR with float64 data (no copy when it already is)."""
    M = M.tocsr()
    return M if M.dtype == np.float64 else M.astype(np.float64)


def transpose_csr(P) -> sp.csr_matrix:
    """``P^T`` as CSR by one counting sort (Gustavson's permuted transposition), compiled.

    Parameters
    ----------
    P : sparse matrix
        ``(m, n)``, converted to CSR with float64 data if it is not already.

    Returns
    -------
    csr_matrix
        ``(n, m)``, every row's column indices increasing; the same matrix as ``P.T.tocsr()``.
    """
    from ._gmg_kernels import transpose

    P = _float_csr(P)
    indptr, indices, data = transpose(_kernel_index(P.indptr), _kernel_index(P.indices), P.data,
                                      P.shape[1])
    return _csr(indptr, indices, data, (P.shape[1], P.shape[0]))


def galerkin_product(A, P, PT=None) -> tuple[sp.csr_matrix, np.ndarray]:
    """The Galerkin coarse operator ``C = P^T A P`` and its diagonal, in one compiled pass.

    Gustavson's row-wise product (Gustavson, "Two fast algorithms for sparse matrices:
    multiplication and permuted transposition", ACM TOMS 4(3), 1978) run over the rows of
    ``P^T``: row ``i`` of ``C`` accumulates ``P_ki a_kj P_j:`` in a dense array of the coarse size
    (with a marker of the row that last touched each column, so nothing is cleared between rows),
    then its columns are sorted (insertion sort: the rows are short). No
    intermediate ``P^T A`` is formed. Nothing is assumed of the numbering or of the number of
    entries per row of ``P``; the work is ``sum_k nnz(P_k:) sum_(j in A_k:) nnz(P_j:)``, small
    when ``P`` has a few entries per row as a P1 prolongation has (1 at a coarse node, 2 at a
    midpoint, fewer after Dirichlet elimination).

    Parameters
    ----------
    A : sparse matrix
        ``(m, m)``; converted to float64 CSR if needed; duplicates and unsorted rows are fine.
    P : sparse matrix
        ``(m, n)`` prolongation; converted to float64 CSR if needed.
    PT : csr_matrix, optional
        ``P^T`` as CSR (e.g. from :func:`transpose_csr`, kept as the restriction); computed if
        not given.

    Returns
    -------
    C : csr_matrix
        ``(n, n)``, canonical (sorted indices, no duplicates; entries that are exactly zero are
        dropped, as SciPy's product drops them). Equal to SciPy's ``P.T @ A @ P`` to round-off
        (the sums run in another order).
    diag : ndarray
        ``C``'s diagonal (0 where ``C`` has no diagonal entry).

    Raises
    ------
    InputError
        The shapes do not match.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.csr_matrix(np.array([[2.0, -1, 0], [-1, 2, -1], [0, -1, 2]]))
    >>> P = sp.csr_matrix(np.array([[1.0, 0], [0.5, 0.5], [0, 1]]))
    >>> C, d = galerkin_product(A, P)
    >>> C.toarray(), d
    (array([[ 1.5, -0.5],
           [-0.5,  1.5]]), array([1.5, 1.5]))
    """
    from ._gmg_kernels import galerkin

    A = _float_csr(A)
    P = _float_csr(P)
    m, n = P.shape
    if A.shape != (m, m):
        raise InputError(f"galerkin_product: A is {A.shape[0]} x {A.shape[1]} but P has {m} rows")
    if PT is None:
        PT = transpose_csr(P)
    elif PT.shape != (n, m):
        raise InputError(f"galerkin_product: P^T must be {n} x {m}, got {PT.shape[0]} x "
                         f"{PT.shape[1]}")
    else:
        PT = _float_csr(PT)
    # the output grows by doubling; start at the fine level's entries per row (P1: the same)
    capacity = A.nnz * n // max(m, 1) + n
    indptr, indices, data, diag = galerkin(
        _kernel_index(PT.indptr), _kernel_index(PT.indices), PT.data,
        _kernel_index(A.indptr), _kernel_index(A.indices), A.data,
        _kernel_index(P.indptr), _kernel_index(P.indices), P.data, capacity)
    C = _csr(indptr, indices, data, (n, n))
    C.has_canonical_format = True  # sorted and summed by construction: no O(nnz) re-check
    return C, diag


class _Level:
    """One level: CSR arrays of ``A_l``, its inverse diagonal and work vectors.

    ``diag``: ``A``'s diagonal when already known (the Galerkin pass returns it, with ``A`` in
    canonical form, so neither is recomputed here).
    """

    __slots__ = ("A", "indptr", "indices", "data", "inv_diag", "x", "r")

    def __init__(self, A: sp.csr_matrix, omega: float, diag: np.ndarray | None = None,
                 finest: bool = False):
        A = A.tocsr()
        A.sum_duplicates()      # no-ops on canonical CSR (flags set by galerkin_product)
        A.sort_indices()
        self.A = A
        self.indptr = _unsigned(A.indptr)
        self.indices = _unsigned(A.indices)
        self.data = A.data
        d = A.diagonal() if diag is None else diag
        check_positive_diagonal(d, what="the gmg preconditioner (a level operator)")
        self.inv_diag = omega / d
        n = A.shape[0]
        # both overwritten before they are read (gs_forward_zero, residual); the finest level's
        # iterate is the cycle's output, a new array (``x`` would be n floats never used)
        self.x = None if finest else np.empty(n)
        self.r = np.empty(n)


class Multigrid:
    """Operators, transfers and the V-cycle of a geometric multigrid hierarchy.

    Parameters
    ----------
    A : sparse matrix
        The finest-level system on the free nodes (symmetric, positive diagonal).
    hierarchy : MeshHierarchy
        Its meshes; ``A`` lives on ``hierarchy.finest``.
    free : array of int or bool mask, optional
        The free (non-Dirichlet) nodes of the finest mesh (``DirichletSystem.free``); default all
        nodes (then ``A`` must have one row per node).
    sweeps : int
        Gauss-Seidel sweeps before and after the coarse correction (V(sweeps, sweeps)).
    omega : float
        Over-relaxation of the sweeps (SOR), in (0, 2).
    coarse_operators : list of sparse matrices, optional
        The operators of levels ``0 .. L-1`` on their free nodes (coarsest first), e.g.
        rediscretised; default Galerkin ``P^T A P`` (:func:`galerkin_product`).
    check_symmetry : bool
        Check ``A`` for symmetry (:class:`~femkit.errors.NotSPDError`); the ``gmg`` factory and
        ``fmg`` skip it when PCG / ``fmg`` already checked (it costs ~ten sparse products).

    Attributes
    ----------
    levels : list
        Per level (coarsest first) the operator and smoother data.
    prolongations : list of csr_matrix
        Free-dof prolongations ``P_l`` (level ``l`` -> ``l + 1``).
    restrictions : list of csc_matrix
        Their transposes ``P_l^T``: views of ``P_l``'s arrays (CSC), no copy.
    frees : list of ndarray
        Free node ids of every level.
    hierarchy : MeshHierarchy
    coarse_factor : Factor
        Direct factorisation of the coarsest operator.
    info : dict
        ``levels``, ``sizes``, ``operator_complexity``, ``grid_complexity``, ``coarse``,
        ``sweeps``, ``smoother``.
    """

    def __init__(self, A, hierarchy, *, free=None, sweeps: int = 2, coarse_operators=None,
                 omega: float = DEFAULT_OMEGA, check_symmetry: bool = True):
        from .kept_factor import factorize_kept

        if hierarchy is None:
            raise _hierarchy_error("geometric multigrid")
        # duck-typed: the solver layer does not import femkit.mesh (docs/architecture.md)
        if not all(hasattr(hierarchy, a) for a in ("level_free", "free_prolongations",
                                                   "fixed_prolongations", "finest")):
            raise HierarchyError(f"hierarchy must be a femkit.mesh.MeshHierarchy, got "
                                 f"{type(hierarchy).__name__}; {ALTERNATIVE}")
        if isinstance(sweeps, bool) or not isinstance(sweeps, (int, np.integer)) or sweeps < 1:
            raise InputError(f"gmg: sweeps must be an integer >= 1, got {sweeps!r}")
        try:
            omega_ok = 0.0 < float(omega) < 2.0
        except (TypeError, ValueError):
            omega_ok = False
        if not omega_ok:
            raise InputError(f"gmg: omega must be a number in (0, 2) (SOR converges for SPD "
                             f"matrices only there), got {omega!r}")
        A = explicit_csr(A, what="the gmg preconditioner")
        if check_symmetry:
            check_symmetric(A, method="the gmg preconditioner")
        n_fine = hierarchy.finest.n_points
        if free is None:
            free = np.ones(n_fine, dtype=bool)
        frees = hierarchy.level_free(free)
        if A.shape[0] != len(frees[-1]):
            raise HierarchyError(
                f"the system has {A.shape[0]} unknowns but the hierarchy's finest mesh has "
                f"{len(frees[-1])} free nodes (of {n_fine}); pass free= (DirichletSystem.free) of "
                f"the finest mesh; {ALTERNATIVE}")
        self.frees = frees
        self.hierarchy = hierarchy
        self.sweeps = int(sweeps)
        P = [_float_csr(p) for p in hierarchy.free_prolongations(frees[-1])]
        self.prolongations = P
        # the restriction P^T is P's arrays read as CSC (no copy): SciPy's CSC product scatters
        # row i of P in increasing i, the order in which a CSR copy of P^T sums its rows, so the
        # results are the same bit for bit; the CSR transpose the Galerkin pass needs is built
        # per level and dropped after it
        self.restrictions = [p.T for p in P]
        self._p_arrays = [(_unsigned(p.indptr), _unsigned(p.indices), p.data) for p in P]
        ops = [A]
        diags = [None] * (len(P) + 1)   # known diagonals (the Galerkin pass returns them)
        if coarse_operators is None:
            for lvl in range(len(P) - 1, -1, -1):
                op, diags[lvl] = galerkin_product(ops[-1], P[lvl], transpose_csr(P[lvl]))
                ops.append(op)
            ops = ops[::-1]
            kind = "galerkin"
        else:
            coarse_operators = list(coarse_operators)
            if len(coarse_operators) != len(P):
                raise InputError(f"gmg: {len(P)} coarse operators expected (levels 0..{len(P) - 1}), "
                                 f"got {len(coarse_operators)}")
            ops = [explicit_csr(c, what="a gmg coarse operator") for c in coarse_operators] + [A]
            for lvl, op in enumerate(ops):
                if op.shape[0] != len(frees[lvl]):
                    raise InputError(f"gmg: coarse operator {lvl} has {op.shape[0]} rows, level "
                                     f"{lvl} has {len(frees[lvl])} free nodes")
            kind = "given"
        self.omega = float(omega)
        top = len(ops) - 1
        self.levels = [_Level(op, self.omega, d, finest=lvl == top)
                       for lvl, (op, d) in enumerate(zip(ops, diags))]
        coarsest = ops[0]
        # the one kept-factor path of the solvers (LinearSession.factorize uses it too): SuperLU
        # in symmetric mode
        self.coarse_factor = factorize_kept(coarsest) if coarsest.shape[0] else None
        nnz = [op.nnz for op in ops]
        sizes = [op.shape[0] for op in ops]
        self.info = {
            "levels": len(ops), "sizes": sizes,
            "operator_complexity": float(sum(nnz) / max(nnz[-1], 1)),
            "grid_complexity": float(sum(sizes) / max(sizes[-1], 1)),
            "coarse": kind, "coarse_size": sizes[0], "sweeps": self.sweeps,
            "smoother": "SOR (forward pre, backward post)", "omega": self.omega,
        }

    @property
    def n_levels(self) -> int:
        return len(self.levels)

    def _coarse_solve(self, b: np.ndarray) -> np.ndarray:
        if self.coarse_factor is None:
            return np.zeros(0)
        return np.asarray(self.coarse_factor.solve(b)).ravel()

    def contraction(self, steps: int = 30, start: int = 0) -> float:
        """Asymptotic energy-norm contraction of the V-cycle's error propagator ``I - M A`` on
        the finest level, by ``steps`` power iterations from a reproducible random error
        (``numpy.random.default_rng(start)``)."""
        A = self.levels[-1].A
        e = np.random.default_rng(start).standard_normal(A.shape[0])
        rho = 0.0
        for _ in range(steps):
            e /= np.sqrt(e @ (A @ e))
            e = e - self.vcycle(A @ e)
            rho = float(np.sqrt(e @ (A @ e)))
        return rho

    def matvec(self, v: np.ndarray, level: int) -> np.ndarray:
        """``A_level v`` written into the level's residual work vector (no allocation), valid
        until the next :meth:`vcycle` or :meth:`matvec` on that level: the same sums in the same
        order as SciPy's CSR product, so the same numbers."""
        from ._gmg_kernels import add_matvec

        L = self.levels[level]
        L.r.fill(0.0)
        add_matvec(L.indptr, L.indices, L.data, np.ascontiguousarray(v, dtype=np.float64), L.r)
        return L.r

    def vcycle(self, b: np.ndarray, level: int | None = None) -> np.ndarray:
        """``M_level b``: one V(sweeps, sweeps)-cycle on ``level`` (default the finest) from zero.

        Returns a new array; the work vectors of the levels below are reused.
        """
        from ._gmg_kernels import add_matvec, gs_forward_zero, gs_sweeps, residual

        top = self.n_levels - 1 if level is None else int(level)
        b = np.ascontiguousarray(b, dtype=np.float64)
        if top == 0:
            return self._coarse_solve(b)
        nu = self.sweeps
        rhs = [None] * (top + 1)
        rhs[top] = b
        out = np.zeros_like(b)
        # down: pre-smooth from zero, restrict the residual
        for lvl in range(top, 0, -1):
            L = self.levels[lvl]
            x = out if lvl == top else L.x
            gs_forward_zero(L.indptr, L.indices, L.data, L.inv_diag, rhs[lvl], x, nu)
            residual(L.indptr, L.indices, L.data, rhs[lvl], x, L.r)
            rhs[lvl - 1] = self.restrictions[lvl - 1] @ L.r
        xc = self._coarse_solve(rhs[0])
        # up: correct, post-smooth backwards
        for lvl in range(1, top + 1):
            L = self.levels[lvl]
            x = out if lvl == top else L.x
            add_matvec(*self._p_arrays[lvl - 1], xc, x)
            gs_sweeps(L.indptr, L.indices, L.data, L.inv_diag, rhs[lvl], x, nu, False)
            xc = x
        return out


def build(A, *, hierarchy=None, free=None, sweeps: int = 2, omega: float = DEFAULT_OMEGA,
          coarse_operators=None) -> Preconditioner:
    """Geometric multigrid preconditioner: one symmetric V(sweeps, sweeps)-cycle per application.

    Parameters
    ----------
    A : sparse matrix
        The system on the free nodes of ``hierarchy.finest``.
    hierarchy : MeshHierarchy
        Required; without it :class:`~femkit.errors.HierarchyError` names ``amg_rs``.
    free : array of int or bool mask, optional
        Free nodes of the finest mesh (``DirichletSystem.free``); default all nodes.
    sweeps : int
        Gauss-Seidel sweeps before (forward) and after (backward) the coarse correction.
    omega : float
        Over-relaxation of the sweeps, in (0, 2) (1: plain Gauss-Seidel); see :data:`DEFAULT_OMEGA`.
    coarse_operators : list of sparse matrices, optional
        Operators of the coarser levels (coarsest first); default Galerkin ``P^T A P``.

    Returns
    -------
    Preconditioner
        ``info``: see :class:`Multigrid` (``hierarchy``: the :class:`Multigrid` object itself).
        ``A``'s symmetry is not checked here: :func:`femkit.solvers.pcg` checks it once.

    Examples
    --------
    >>> import numpy as np
    >>> from femkit.mesh import Mesh, MeshHierarchy, boundary_nodes
    >>> from femkit.fem import assemble_stiffness, apply_dirichlet
    >>> from femkit.solvers import pcg
    >>> sq = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], triangles=[[0, 1, 2], [0, 2, 3]])
    >>> H = MeshHierarchy.from_refinement(sq, 5)
    >>> K = assemble_stiffness(H.finest)
    >>> sys = apply_dirichlet(K, np.ones(H.finest.n_points), boundary_nodes(H.finest), 0.0)
    >>> M = build(sys.A, hierarchy=H, free=sys.free)
    >>> res = pcg(sys.A, sys.b, M=M, rtol=1e-8)
    >>> res.converged, res.iterations <= 8, M.info["levels"]
    (True, True, 6)
    """
    if hierarchy is None:
        raise _hierarchy_error("preconditioner 'gmg'")
    t0 = time.perf_counter()
    with dependency_boundary("preconditioner 'gmg' (set-up)", A):
        mg = Multigrid(A, hierarchy, free=free, sweeps=sweeps, coarse_operators=coarse_operators,
                       omega=omega, check_symmetry=False)  # pcg checks A once
    info = dict(mg.info)
    info["hierarchy"] = mg
    return Preconditioner("gmg", mg.vcycle, mg.levels[-1].A.shape[0],
                          time.perf_counter() - t0, info)
