"""A Poisson problem ``-div(kappa grad u) = f`` with Dirichlet and Neumann data, end to end.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> pts = np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.], [.5, .5]])
>>> tri = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
>>> prob = PoissonProblem(Mesh(pts, tri), f=0.0, dirichlet=[(None, lambda x, y: x + y)])
>>> u, result = prob.solve()
>>> round(float(u[4]), 12)
1.0
"""

from __future__ import annotations

import time
from typing import Callable, NamedTuple, Sequence

import numpy as np

from ..errors import InputError, SingularSystemError
from .coefficients import Coefficient
from .dirichlet import DirichletSystem, apply_dirichlet, dirichlet_values
from .load import assemble_load
from .neumann import assemble_neumann
from .p1_stiffness import assemble_stiffness
from .sparsity import SparsityPattern


class PoissonSolution(NamedTuple):
    """``u`` (full nodal vector) and the solver's ``SolveResult``."""

    u: np.ndarray
    result: object


class PoissonProblem:
    """Mesh + coefficient + source + boundary conditions of ``-div(kappa grad u) = f``.

    Parameters
    ----------
    mesh : Mesh
    kappa : float, (m,) array, {cell tag or name: value} or callable kappa(x, y)
    f : float or callable f(x, y)
    dirichlet : sequence of (tags or None, g)
        ``u = g`` on boundary edges with those tags (``None``: the whole boundary, found
        topologically); ``g`` a number, callable g(x, y). Later entries win on shared nodes.
    neumann : sequence of (tags, h)
        Outward flux ``kappa du/dn = h`` on those boundary edges.
    load_rule : str
        Quadrature rule of the load (``barycentric`` default; ``gauss3``, ``gauss6``, ``gauss7``).

    Attributes
    ----------
    timings : dict
        Seconds spent per stage of the last :meth:`assemble` / :meth:`solve`
        (``pattern``, ``stiffness``, ``load``, ``neumann``, ``dirichlet``, ``solve``).
    """

    def __init__(self, mesh, kappa: Coefficient = 1.0, f=0.0, *,
                 dirichlet: Sequence = ((None, 0.0),), neumann: Sequence = (),
                 load_rule: str = "barycentric"):
        self.mesh = mesh
        self.kappa = kappa
        self.f = f
        self.dirichlet = [tuple(d) for d in dirichlet]
        self.neumann = [tuple(d) for d in neumann]
        self.load_rule = load_rule
        self.timings: dict[str, float] = {}
        self.system: DirichletSystem | None = None
        if not self.dirichlet:
            raise SingularSystemError(
                "no Dirichlet condition: the pure Neumann Poisson problem is singular (fix u somewhere)")
        for entry in self.dirichlet + self.neumann:
            if len(entry) != 2:
                raise InputError(f"boundary conditions are (tags, value) pairs, got {entry!r}")

    def assemble(self) -> DirichletSystem:
        """Assemble K, F (+ Neumann) and eliminate the Dirichlet nodes; stage times in ``timings``."""
        t = {}
        t0 = time.perf_counter()
        pattern = SparsityPattern.for_mesh(self.mesh)
        t["pattern"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        K = assemble_stiffness(self.mesh, self.kappa, pattern=pattern)
        t["stiffness"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        F = assemble_load(self.mesh, self.f, rule=self.load_rule)
        t["load"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        for tags, h in self.neumann:
            F += assemble_neumann(self.mesh, tags, h)
        t["neumann"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        g = np.full(self.mesh.n_points, np.nan)
        for tags, value in self.dirichlet:
            nodes = _boundary_nodes(self.mesh, tags)
            g[nodes] = dirichlet_values(self.mesh, nodes, value)
        fixed = np.flatnonzero(~np.isnan(g))
        self.system = apply_dirichlet(K, F, fixed, g[fixed])
        t["dirichlet"] = time.perf_counter() - t0
        self.timings = t
        return self.system

    def solve(self, method: str = "direct", preconditioner=None, **solver_opts) -> PoissonSolution:
        """Assemble (if not done) and solve; returns ``(u, SolveResult)``.

        ``method``, ``preconditioner`` and ``solver_opts`` (rtol, atol, maxiter, ...) go to
        :func:`femkit.solvers.solve`.
        """
        system = self.system if self.system is not None else self.assemble()
        t0 = time.perf_counter()
        result = _solve(system.A, system.b, method=method, preconditioner=preconditioner, **solver_opts)
        self.timings["solve"] = time.perf_counter() - t0
        return PoissonSolution(system.expand(result.x), result)


def _boundary_nodes(mesh, tags) -> np.ndarray:
    try:
        from ..mesh import boundary_nodes
    except ImportError:  # pragma: no cover - mesh package without it
        boundary_nodes = _boundary_nodes_fallback
    return boundary_nodes(mesh, tags)


def _boundary_nodes_fallback(mesh, tags) -> np.ndarray:
    if tags is None:
        tri = mesh.triangles
        e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        uniq, counts = np.unique(e, axis=0, return_counts=True)
        return np.unique(uniq[counts == 1])
    from .neumann import tagged_edges

    return np.unique(tagged_edges(mesh, tags))


def _solve(A, b, *, method, preconditioner, **opts):
    try:
        from ..solvers import solve
    except ImportError:  # pragma: no cover - solver layer absent
        solve = None
    if solve is not None:
        return solve(A, b, method=method, preconditioner=preconditioner, **opts)
    from scipy.sparse.linalg import spsolve  # pragma: no cover

    from ..solvers.result import SolveResult  # pragma: no cover

    x = spsolve(A.tocsc(), b)  # pragma: no cover
    res = float(np.linalg.norm(b - A @ x))  # pragma: no cover
    return SolveResult(x=x, converged=True, iterations=0, residuals=np.array([res]), reason="direct",
                       true_residual=res, rhs_norm=float(np.linalg.norm(b)), method="direct")  # pragma: no cover
