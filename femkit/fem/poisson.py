"""A Poisson problem ``-div(kappa grad u) = f`` with Dirichlet and Neumann data, end to end.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> pts = np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.], [.5, .5]])
>>> tri = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
>>> prob = PoissonProblem(Mesh(pts, tri), f=0.0, dirichlet=[(None, lambda x, y: x + y)])
>>> u, result = prob.solve()
>>> round(float(u[4]), 12)
1.0

Pure Neumann (no Dirichlet data): the solution is fixed up to a constant, here by its mean.

>>> prob = PoissonProblem(Mesh(pts, tri), f=0.0, dirichlet=[], neumann=[(None, 0.0)])
>>> u, result = prob.solve()
>>> bool(np.abs(u).max() < 1e-12), prob.system.mode
(True, 'mean_zero')

Pure Neumann problems
---------------------
Without Dirichlet data ``K`` is singular (``K 1 = 0``) and ``K u = F`` is solvable only when
the discrete compatibility condition ``1^T F = int f dx + int h ds = 0`` holds.
:func:`check_compatibility` raises :class:`~femkit.errors.SingularSystemError` when
``|sum F| > rtol * sum |F|`` and otherwise removes the small remainder (a quadrature error of
``int f``) by subtracting the matching constant from ``f``. The constant in ``u`` is then
fixed by the ``nullspace`` mode (:func:`pure_neumann_system`):

- ``mean_zero`` (default): the solution with ``int u_h dx = 0``. The direct solver gets the
  bordered (Lagrange-multiplier) matrix ``[[K, w], [w^T, 0]]`` with ``w_i = int N_i dx``,
  symmetric indefinite, so it is factorised by LU, never Cholesky. Iterative methods solve
  the SPD system with one node pinned to 0 and the result is shifted to mean zero: plain CG
  would also converge on the singular but consistent ``K u = F``, but smoothed-aggregation
  AMG and IC(0) built on a singular matrix are not reliably positive definite (measured:
  ``r^T M r < 0`` breakdowns), and the pinned system works with every preconditioner.
- ``pin``: ``u = value`` at one node (eliminated like a Dirichlet node): an SPD system of
  ``n - 1`` unknowns for any solver.
- ``error``: raise :class:`PureNeumannError`.

:class:`PureNeumannError` is a :class:`~femkit.errors.SingularSystemError` and an
:class:`~femkit.errors.InputError`: the data are at fault, so ``femkit solve`` exits with 2.

The discrete solutions of ``pin`` and ``mean_zero`` differ by a constant only. Compare a
pure-Neumann solution with an exact solution modulo the constant: :func:`mean_shift`.
"""

from __future__ import annotations

from typing import Callable, NamedTuple, Sequence

import numpy as np

from ..errors import InputError, PureNeumannError, SingularSystemError  # noqa: F401 (re-exported)
from ..mesh.edges import boundary_nodes
from ..timing import StageTimer
from ._elements import select_elements, simplex_gradients, triangle_geometry
from .coefficients import Coefficient, evaluate_callable
from .dirichlet import DirichletSystem, apply_dirichlet, dirichlet_values
from .load import assemble_load
from .neumann import assemble_neumann
from .p1_stiffness import assemble_stiffness
from .sparsity import SparsityPattern


NULLSPACE_MODES = ("mean_zero", "pin", "error")


#: default of ``compatibility_rtol``: |int f + int h| relative to sum |F| accepted as quadrature error
COMPATIBILITY_RTOL = 1e-3


def node_weights(mesh, *, elements=None) -> np.ndarray:
    """``w_i = int N_i dx`` (a third of the area of each triangle, a quarter of the volume of each
    tetrahedron around node i); ``sum w = |Omega|``.

    >>> from femkit.mesh import Mesh
    >>> node_weights(Mesh(np.array([[0., 0.], [3., 0.], [0., 2.]]), np.array([[0, 1, 2]]))).tolist()
    [1.0, 1.0, 1.0]
    """
    if mesh.dim == 3:
        _, vol, tets = simplex_gradients(mesh, select_elements(mesh, elements))
        return np.bincount(tets.ravel(), weights=np.repeat(vol / 4.0, 4), minlength=mesh.n_points)
    _, area, _, tri = triangle_geometry(mesh, select_elements(mesh, elements))
    return np.bincount(tri.ravel(), weights=np.repeat(area / 3.0, 3), minlength=mesh.n_points)


def check_compatibility(F_source: np.ndarray, F_flux=None, *, weights: np.ndarray | None = None,
                        rtol: float | None = None) -> tuple[np.ndarray, dict]:
    """Check ``int f dx + int h ds = 0`` on the discrete load of a pure-Neumann problem.

    Parameters
    ----------
    F_source, F_flux : ndarray, shape (n,)
        Load vectors of the source and of the Neumann fluxes (``F_flux`` may be None).
    weights : ndarray, shape (n,), optional
        ``int N_i dx`` (:func:`node_weights`); the remainder is removed as a constant source,
        ``F - (sum F) w / sum w``. Without it, a uniform shift of ``F``.
    rtol : float, optional
        Largest ``|sum F| / sum |F|`` accepted (the quadrature error of ``int f``; default
        :data:`COMPATIBILITY_RTOL`, read at the call).

    Returns
    -------
    F : ndarray
        The consistent load (``sum F = 0`` to rounding).
    info : dict
        ``source_integral``, ``flux_integral``, ``relative_imbalance``, ``rtol``.

    Raises
    ------
    PureNeumannError
        (a SingularSystemError and an InputError) ``|sum F| > rtol * sum |F|``: the data
        admit no solution.

    >>> F, info = check_compatibility(np.array([1.0, -1.0 + 1e-9]))
    >>> bool(abs(F.sum()) < 1e-15), info["relative_imbalance"] < 1e-8
    (True, True)
    >>> check_compatibility(np.array([1.0, 1.0]))
    Traceback (most recent call last):
    ...
    femkit.errors.PureNeumannError: pure-Neumann data are incompatible: int f dx = 2 and int h ds = 0 must sum to 0 (relative imbalance 1 > 0.001); change the source or the fluxes so they balance, or add a Dirichlet condition
    """
    F_source = np.asarray(F_source, dtype=np.float64)
    F_flux = np.zeros_like(F_source) if F_flux is None else np.asarray(F_flux, dtype=np.float64)
    F = F_source + F_flux
    total = float(F.sum())
    info = compatibility_facts(float(F_source.sum()), float(F_flux.sum()),
                               float(np.abs(F_source).sum() + np.abs(F_flux).sum()), rtol)
    if weights is None:
        return F - total / len(F), info
    weights = np.asarray(weights, dtype=np.float64)
    return F - total * weights / weights.sum(), info


def compatibility_facts(source_integral: float, flux_integral: float, scale: float,
                        rtol: float | None = None) -> dict:
    """The compatibility check of :func:`check_compatibility` on the sums alone (a distributed
    run reduces them over ranks): ``scale = sum |F_source| + sum |F_flux|``; ``rtol`` None:
    :data:`COMPATIBILITY_RTOL`."""
    rtol = COMPATIBILITY_RTOL if rtol is None else rtol
    total = source_integral + flux_integral
    rel = abs(total) / scale if scale > 0 else 0.0
    info = {"source_integral": source_integral, "flux_integral": flux_integral,
            "relative_imbalance": rel, "rtol": float(rtol)}
    if rel > rtol:
        raise PureNeumannError(
            f"pure-Neumann data are incompatible: int f dx = {info['source_integral']:.6g} and "
            f"int h ds = {info['flux_integral']:.6g} must sum to 0 (relative imbalance "
            f"{rel:.3g} > {rtol:g}); change the source or the fluxes so they balance, or add a "
            "Dirichlet condition")
    return info


class NullspaceSystem:
    """A pure-Neumann system with its constant fixed; the same interface as DirichletSystem.

    Attributes
    ----------
    A, b : the matrix and right-hand side handed to the solver (``A`` is ``K`` itself,
        the bordered ``(n+1) x (n+1)`` matrix, or the SPD matrix with one node eliminated).
    mode : ``"mean_zero"`` or ``"pin"``.
    free, fixed : node indices (``fixed`` holds the pinned node, or nothing).
    n : number of nodes; ``weights``: ``int N_i dx``; ``compatibility``: the check's facts.
    """

    def __init__(self, A, b, mode: str, n: int, weights: np.ndarray, *, bordered: bool = False,
                 pinned: DirichletSystem | None = None, compatibility: dict | None = None):
        self.A, self.b, self.mode, self.n = A, b, mode, n
        self.weights = weights
        self.bordered = bordered
        self.pinned = pinned
        self.compatibility = compatibility or {}
        self.fixed = pinned.fixed if pinned is not None else np.zeros(0, dtype=np.int64)
        self.free = pinned.free if pinned is not None else np.arange(n)

    def expand(self, x: np.ndarray) -> np.ndarray:
        """Full nodal vector from the solver's ``x`` (mean-zero mode: shifted to ``int u = 0``)."""
        if self.pinned is not None:
            u = self.pinned.expand(x)
        else:
            x = np.asarray(x, dtype=np.float64)
            if x.shape != (self.n + 1,):
                raise InputError(f"expected {self.n + 1} values, got shape {x.shape}")
            u = x[:self.n]
        if self.mode == "pin":
            return u
        return u - float(self.weights @ u) / float(self.weights.sum())


def pure_neumann_system(K, F, *, mode: str = "mean_zero", weights: np.ndarray, method: str = "direct",
                        pin_node: int = 0, pin_value: float = 0.0,
                        compatibility: dict | None = None) -> NullspaceSystem:
    """Fix the constant of the singular pure-Neumann system ``K u = F`` (``F`` consistent).

    Parameters
    ----------
    K : sparse matrix (n, n), symmetric with ``K 1 = 0``.
    F : ndarray (n,) with ``sum F = 0`` (see :func:`check_compatibility`).
    mode : ``mean_zero``, ``pin`` or ``error`` (raises SingularSystemError).
    weights : ``int N_i dx`` (:func:`node_weights`).
    method : the solver that will be used: ``direct`` gets the bordered matrix in mean-zero mode,
        the others the SPD system with ``pin_node`` eliminated (then shifted to mean zero).
    pin_node, pin_value : the node pinned, and its value in ``pin`` mode.
    """
    import scipy.sparse as sp

    if mode not in NULLSPACE_MODES:
        raise InputError(f"unknown nullspace mode {mode!r}; valid modes: {', '.join(NULLSPACE_MODES)}")
    if mode == "error":
        raise PureNeumannError(
            "no Dirichlet condition: the pure-Neumann Poisson problem is singular (u is fixed only "
            "up to a constant); choose nullspace 'mean_zero' or 'pin', or add a Dirichlet condition")
    n = K.shape[0]
    if mode == "mean_zero" and method == "direct":
        w = sp.csr_matrix(np.asarray(weights, dtype=np.float64)[None, :])
        A = sp.bmat([[K, w.T], [w, None]], format="csr")
        A.sort_indices()
        return NullspaceSystem(A, np.append(F, 0.0), mode, n, weights, bordered=True,
                               compatibility=compatibility)
    if not 0 <= int(pin_node) < n:
        raise InputError(f"pin node {pin_node} out of range 0..{n - 1}")
    value = float(pin_value) if mode == "pin" else 0.0
    pinned = apply_dirichlet(K, F, [int(pin_node)], [value])
    return NullspaceSystem(pinned.A, pinned.b, mode, n, weights, pinned=pinned,
                           compatibility=compatibility)


def mean_shift(mesh, u: np.ndarray, exact: Callable, *, order: int = 5) -> float:
    """The constant ``c`` with ``int (u_h - c - u) dx = 0``: compare ``u_h - c`` with ``exact``.

    ``int u_h`` is exact (``w . u``); ``int u`` uses a quadrature rule of degree ``order``.

    >>> from femkit.mesh import Mesh
    >>> m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
    >>> round(mean_shift(m, np.array([3., 4., 3.]), lambda x, y: x), 12)
    3.0
    """
    uh, ue, area = mean_shift_parts(mesh, u, exact, order=order)
    return (uh - ue) / area


def mean_shift_parts(mesh, u: np.ndarray, exact: Callable, *, order: int = 5,
                     elements=None) -> tuple[float, float, float]:
    """``(int u_h, int u, area)`` over the selected elements: the integrals :func:`mean_shift`
    combines, which a distributed run sums over ranks first (``u`` is read only at the
    selected elements' nodes)."""
    from .quadrature import rule_for_degree

    rule = rule_for_degree(order, mesh.dim)
    idx = select_elements(mesh, elements)
    if mesh.dim == 3:
        _, area, tri = simplex_gradients(mesh, idx)
    else:
        _, area, _, tri = triangle_geometry(mesh, idx)
    xy = rule.physical_points(mesh, tri)
    exact_integral = float(area @ (evaluate_callable(exact, *xy, name="exact") @ rule.weights))
    uh_integral = float((area / (mesh.dim + 1.0)) @ np.asarray(u, dtype=np.float64)[tri].sum(axis=1))
    return uh_integral, exact_integral, float(area.sum())


class PoissonSolution(NamedTuple):
    """``u`` (full nodal vector) and the solver's ``SolveResult``."""

    u: np.ndarray
    result: object


class PoissonProblem:
    """Mesh + coefficient + source + boundary conditions of ``-div(kappa grad u) = f``.

    Parameters
    ----------
    mesh : Mesh
        Triangles or tetrahedra; on tetrahedra every callable takes ``(x, y, z)``.
    kappa : float, (m,) array, {cell tag or name: value} or callable kappa(x, y)
    f : float or callable f(x, y)
    dirichlet : sequence of (tags or None, g)
        ``u = g`` on boundary facets (edges, faces) with those tags (``None``: the whole
        boundary, found topologically); ``g`` a number, callable g(x, y). Later entries win on
        shared nodes.
    neumann : sequence of (tags, h)
        Outward flux ``kappa du/dn = h`` on those boundary facets.
    load_rule : str
        Quadrature rule of the load (``barycentric`` default; triangles ``gauss3``, ``gauss6``,
        ``gauss7``; tetrahedra ``gauss4``, ``stroud8``, ``stroud27``, ``stroud64``).
    nullspace : {"mean_zero", "pin", "error"}, optional
        Only without Dirichlet data (pure Neumann, ``dirichlet=[]``): how the constant is
        fixed (default ``mean_zero``; see the module docstring). Giving it together with
        Dirichlet data is an InputError.
    compatibility_rtol : float
        Pure Neumann: largest accepted ``|int f + int h| / sum |F|`` (default 1e-3).
    pin_node, pin_value : int, float
        Pure Neumann, ``nullspace="pin"``: the node fixed and its value.
    element : {"P1", "P2"}
        The finite element (:data:`femkit.elements.ELEMENTS`). P2: the stiffness and mass of
        :mod:`femkit.fem.forms`, the load, fluxes, Dirichlet dofs (vertices and edge midpoints)
        and errors of :mod:`femkit.fem.lagrange`; ``u`` then has one value per dof
        (:func:`femkit.fem.dofs.dof_map`: the nodes first). P2's load rule is the degree-4 rule
        unless ``load_rule`` names another than P1's default ``barycentric``.

    Attributes
    ----------
    timings : dict
        Seconds spent per stage of the last :meth:`assemble` / :meth:`solve`
        (``pattern``, ``stiffness``, ``load``, ``neumann``, ``dirichlet``, ``solve``).
    system : DirichletSystem or NullspaceSystem
        The system of the last :meth:`assemble`.
    """

    def __init__(self, mesh, kappa: Coefficient = 1.0, f=0.0, *,
                 dirichlet: Sequence = ((None, 0.0),), neumann: Sequence = (),
                 load_rule: str = "barycentric", nullspace: str | None = None,
                 compatibility_rtol: float = COMPATIBILITY_RTOL, pin_node: int = 0,
                 pin_value: float = 0.0, element: str = "P1"):
        from ..elements import get_element

        self.element = get_element(element, mesh.dim)
        self.mesh = mesh
        self.kappa = kappa
        self.f = f
        self.dirichlet = [tuple(d) for d in dirichlet]
        self.neumann = [tuple(d) for d in neumann]
        self.load_rule = load_rule
        self._timer = StageTimer()
        self.system: DirichletSystem | NullspaceSystem | None = None
        if self.dirichlet and nullspace is not None:
            raise InputError("nullspace only applies to pure-Neumann problems (no Dirichlet data)")
        if nullspace is not None and nullspace not in NULLSPACE_MODES:
            raise InputError(f"unknown nullspace mode {nullspace!r}; valid modes: "
                             f"{', '.join(NULLSPACE_MODES)}")
        self.nullspace = None if self.dirichlet else (nullspace or "mean_zero")
        self.compatibility_rtol = float(compatibility_rtol)
        self.pin_node, self.pin_value = int(pin_node), float(pin_value)
        if self.nullspace == "error":
            pure_neumann_system(None, None, mode="error", weights=None)
        for entry in self.dirichlet + self.neumann:
            if len(entry) != 2:
                raise InputError(f"boundary conditions are (tags, value) pairs, got {entry!r}")

    @property
    def timings(self) -> dict[str, float]:
        """Seconds per stage of the last assembly and solve."""
        return self._timer.times

    def assemble_matrices(self, *, keep_pattern: bool = True) -> tuple:
        """Stiffness ``K`` and load ``F`` (source + Neumann fluxes) on the whole mesh.

        The Neumann part alone is kept as :attr:`neumann_load` (the pure-Neumann compatibility
        check needs it). Stage times go to :attr:`timings`. ``keep_pattern=False``: a one-off
        assembly that builds and caches no sparsity pattern on a large triangle mesh
        (:func:`assemble_stiffness`'s ``keep_pattern``; the same ``K``).
        """
        self._timer = StageTimer()
        t = self._timer
        if self.element.name != "P1":
            return self._assemble_element()
        with t("pattern"):
            pattern = (SparsityPattern.for_mesh(self.mesh) if keep_pattern
                       else SparsityPattern.cached(self.mesh))
        with t("stiffness"):
            K = assemble_stiffness(self.mesh, self.kappa, pattern=pattern, keep_pattern=keep_pattern)
        with t("load"):
            F = assemble_load(self.mesh, self.f, rule=self.load_rule)
        with t("neumann"):
            F_flux = self.neumann_vector()
        self.neumann_load = F_flux
        return K, F + F_flux

    def _assemble_element(self) -> tuple:
        """:meth:`assemble_matrices` for an element other than P1 (:mod:`femkit.fem.forms`,
        :mod:`femkit.fem.lagrange`)."""
        from .forms import assemble_matrix
        from .lagrange import element_load

        t = self._timer
        with t("stiffness"):   # with its pattern (one pass on a large mesh, forms.assemble_matrix)
            K = assemble_matrix(self.mesh, "stiffness", self.kappa, element=self.element)
        with t("load"):
            rule = None if self.load_rule == "barycentric" else self.load_rule
            F = element_load(self.mesh, self.f, self.element, rule=rule)
        with t("neumann"):
            F_flux = self.neumann_vector()
        self.neumann_load = F_flux
        return K, F + F_flux

    @property
    def dofs(self):
        """The :class:`~femkit.fem.dofs.DofMap` of the problem's element on its mesh."""
        from .dofs import dof_map

        return dof_map(self.mesh, self.element)

    @property
    def n_dofs(self) -> int:
        """Unknowns before boundary conditions (nodes for P1; nodes + edges for P2)."""
        return self.mesh.n_points if self.element.name == "P1" else self.dofs.n_dofs

    def dirichlet_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Dirichlet dofs (sorted) and their values; a later entry wins on shared dofs. P1: the
        nodes; P2: the nodes and edge midpoints of the tagged facets (``g`` interpolated)."""
        if self.element.name != "P1":
            return self._element_dirichlet()
        g = np.full(self.mesh.n_points, np.nan)
        for tags, value in self.dirichlet:
            nodes = boundary_nodes(self.mesh, tags)
            g[nodes] = dirichlet_values(self.mesh, nodes, value)
        fixed = np.flatnonzero(~np.isnan(g))
        return fixed, g[fixed]

    def _element_dirichlet(self) -> tuple[np.ndarray, np.ndarray]:
        from types import SimpleNamespace

        from .lagrange import boundary_dofs

        dofs = self.dofs
        at = SimpleNamespace(points=dofs.points(self.mesh))  # g at the dof points
        g = np.full(dofs.n_dofs, np.nan)
        for tags, value in self.dirichlet:
            ids = boundary_dofs(self.mesh, dofs, tags)
            g[ids] = dirichlet_values(at, ids, value)
        fixed = np.flatnonzero(~np.isnan(g))
        return fixed, g[fixed]

    def neumann_vector(self) -> np.ndarray:
        """``int h N_i ds`` summed over the Neumann entries, shape (n_dofs,)."""
        F_flux = np.zeros(self.n_dofs)
        for tags, h in self.neumann:
            if self.element.name == "P1":
                F_flux += assemble_neumann(self.mesh, tags, h)
            else:
                from .lagrange import element_neumann

                F_flux += element_neumann(self.mesh, tags, h, self.element)
        return F_flux

    def weights(self) -> np.ndarray:
        """``int phi_i dx`` per dof (:func:`node_weights` for P1)."""
        if self.element.name == "P1":
            return node_weights(self.mesh)
        from .lagrange import dof_weights

        return dof_weights(self.mesh, self.element)

    def reduce(self, K, F, method: str = "direct", *, overwrite: bool = False) -> DirichletSystem | NullspaceSystem:
        """The system a solver gets: Dirichlet nodes eliminated (SPD), or, pure Neumann, the
        compatibility checked and the constant fixed (:func:`pure_neumann_system`; ``method``
        says whether a direct solver will be used). ``overwrite``: the Dirichlet elimination
        may reuse ``K``'s arrays (:func:`apply_dirichlet`; ``K`` is not to be used after)."""
        with self._timer("dirichlet"):
            if self.nullspace is not None:
                w = self.weights()
                F_flux = getattr(self, "neumann_load", np.zeros_like(F))
                F, info = check_compatibility(F - F_flux, F_flux, weights=w,
                                              rtol=self.compatibility_rtol)
                self.system = pure_neumann_system(K, F, mode=self.nullspace, weights=w, method=method,
                                                  pin_node=self.pin_node, pin_value=self.pin_value,
                                                  compatibility=info)
            else:
                fixed, values = self.dirichlet_data()
                self.system = apply_dirichlet(K, F, fixed, values, overwrite=overwrite)
        return self.system

    def assemble(self, method: str = "direct") -> DirichletSystem | NullspaceSystem:
        """:meth:`assemble_matrices` then :meth:`reduce`; stage times in ``timings``."""
        return self.reduce(*self.assemble_matrices(), method=method)

    def solve(self, method="direct", preconditioner=None, **solver_opts) -> PoissonSolution:
        """Assemble (if not done) and solve; returns ``(u, SolveResult)``.

        ``method`` is a solver name or a :class:`~femkit.solvers.SolverSpec`; a name goes with
        ``preconditioner`` and ``solver_opts`` (rtol, atol, maxiter, ...) to
        :func:`femkit.solvers.solve`, a spec is used as it is (``solver_opts`` override its
        stopping rule).
        """
        from ..solvers import SolverSpec, solve

        name = method.method if isinstance(method, SolverSpec) else method
        system = self.system
        if system is None or (isinstance(system, NullspaceSystem)
                              and system.bordered != (name == "direct" and system.mode == "mean_zero")):
            system = self.assemble(name)  # bordered only for a direct mean-zero solve
        with self._timer("solve"):
            if isinstance(method, SolverSpec):
                result = method.solve(system.A, system.b, **solver_opts)
            else:
                result = solve(system.A, system.b, method=method, preconditioner=preconditioner,
                               **solver_opts)
        return PoissonSolution(system.expand(result.x), result)

    def errors(self, u: np.ndarray, exact: Callable, grad_exact: Callable | None = None, *,
               order: int = 5) -> dict:
        """L2 / H1-seminorm / max-nodal errors of ``u`` (:func:`femkit.fem.error_norms`).

        Pure Neumann: modulo the constant, i.e. of ``u - c`` with ``int (u - c - exact) = 0``
        (:func:`mean_shift`).
        """
        from .norms import error_norms

        if self.element.name != "P1":
            from .lagrange import element_error_norms

            if self.nullspace is not None:
                _, ue, area = mean_shift_parts(self.mesh, np.zeros(self.mesh.n_points), exact, order=order)
                u = u - (float(self.weights() @ u) - ue) / area
            errs = element_error_norms(self.mesh, u, exact, grad_exact, element=self.element, order=order)
            return {k: (None if v is None else float(v)) for k, v in errs.items()}
        if self.nullspace is not None:
            u = u - mean_shift(self.mesh, u, exact, order=order)
        errs = error_norms(self.mesh, u, exact, grad_exact, order=order)
        return {k: (None if v is None else float(v)) for k, v in errs.items()}

