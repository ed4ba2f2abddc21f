"""``femkit check``: cross-check a Poisson case against scikit-fem and pyamg on the same mesh.

Compared quantities and their documented tolerances (docs/cli.md):

- stiffness K: ``||K - K_skfem||_F / ||K_skfem||_F`` <= 1e-12 (``element: P2``: scikit-fem's
  ``ElementTriP2`` / ``ElementTetP2``, its dofs renumbered to femkit's; the load with P2's rule);
- load F (the case's ``quadrature.load`` rule, scikit-fem's ``Basis`` given the same points and
  weights): ``||F - F_skfem|| / ||F_skfem||`` <= 1e-12;
- solution vs skfem (condense + direct solve): ``||u - u_skfem|| / ||u_skfem||`` <=
  ``SOLUTION_FACTOR * rtol``;
- solution vs pyamg (its own SA solver, ``accel='cg'``, same rtol) on the reduced system:
  ``||u - u_pyamg|| / ||u_pyamg||`` <= ``SOLUTION_FACTOR * rtol``.

Both iterative solutions satisfy a relative residual of ``rtol``; their difference is bounded
by ``cond(A) * rtol`` in theory, and observed far below ``10 * rtol`` on the bundled cases.
Solution tolerances are never tighter than ``1e-10`` (round-off of a direct solve).
The load row uses the source term only, integrated by the same rule on both sides (so the
solutions solve the same discrete problem); Neumann terms, when present, are femkit's in both
solution rows.
Pure-Neumann cases: the solutions are compared at mean zero (``int u dx = 0``), scikit-fem's
with node 0 pinned, pyamg's on the pinned SPD system.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..load import Case

__all__ = ["CheckRow", "cross_check", "format_table", "MATRIX_TOL", "SOLUTION_FACTOR"]

#: Relative tolerance of the stiffness matrix and load comparisons.
MATRIX_TOL = 1e-12
#: Solution tolerance = SOLUTION_FACTOR * solver.rtol (at least SOLUTION_FLOOR).
SOLUTION_FACTOR = 10.0
SOLUTION_FLOOR = 1e-10


@dataclass
class CheckRow:
    """One compared quantity: its relative difference and the tolerance it must meet."""

    name: str
    difference: float
    tolerance: float
    detail: str = ""

    @property
    def passed(self) -> bool:
        return bool(np.isfinite(self.difference) and self.difference <= self.tolerance)


def _rel(a, b) -> float:
    den = float(np.linalg.norm(b))
    num = float(np.linalg.norm(a - b))
    return num / den if den > 0 else num


def _require(module: str, package: str):
    """Import ``module``; a missing package is one line naming how to install it (exit code 2)."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        from ...errors import InputError

        raise InputError(f"femkit check needs {package}, which is not installed; install it with "
                         f"`python -m pip install {package}` (it is a dependency of femkit: "
                         "reinstall femkit to get it)") from None


def cross_check(case: Case) -> list[CheckRow]:
    """Run the comparisons of the module docstring; returns the rows (nothing written)."""
    if case.problem != "poisson":
        from ...errors import CaseFileError

        raise CaseFileError(f"femkit check handles 'poisson' cases, not {case.problem!r}")
    import scipy.sparse.linalg as spla
    _require("skfem", "scikit-fem")
    _require("pyamg", "pyamg")

    from ...fem.load import assemble_load
    from . import reference
    from .problem import build_mesh_levels, is_pure_neumann, multigrid_inputs, poisson_problem

    mesh, hierarchy = build_mesh_levels(case)
    problem = poisson_problem(case, mesh)
    K, F = problem.assemble_matrices()
    kappa = problem.kappa
    neumann = problem.neumann_load
    rule = problem.load_rule  # the case's quadrature.load: scikit-fem integrates with it too
    element = problem.element.name
    if element == "P1":
        F_source = assemble_load(mesh, problem.f, rule=rule)  # the source's part of F alone
    else:
        from ...fem.lagrange import element_load, load_rule

        if rule == "barycentric":  # P2's own rule (the cheapest exact for its products)
            rule = load_rule(problem.element).name
        F_source = element_load(mesh, problem.f, problem.element, rule=rule)
    K_sk, F_sk = reference.assemble(mesh, kappa, case.functions["source"], rule=rule,
                                    **({} if element == "P1" else {"element": element}))
    rows = [
        CheckRow("stiffness K vs scikit-fem", float(spla.norm(K - K_sk) / spla.norm(K_sk)),
                 MATRIX_TOL, f"{K.shape[0]}x{K.shape[1]}, nnz {K.nnz}"),
        CheckRow("load F vs scikit-fem", _rel(F_source, F_sk), MATRIX_TOL,
                 f"quadrature {rule!r} on both sides"),
    ]

    # Our solution with the case's solver.
    system = problem.reduce(K, F, case.solver.method)
    mg = multigrid_inputs(case, hierarchy, system)
    if case.solver.method == "fmg":  # it stops at the discretisation error; the check needs rtol
        mg["options"]["target"] = "residual"
    res = case.solver.solve(system.A, system.b, **mg)
    u = system.expand(res.x)
    spec = case.solver
    sol_tol = max(SOLUTION_FACTOR * spec.rtol, SOLUTION_FLOOR)

    F_sk = F_sk + neumann
    pure = is_pure_neumann(case)
    if pure:
        # u is defined up to a constant: skfem pins node 0, both compared at mean zero
        from ...fem.poisson import (
            check_compatibility,
            node_weights,
            pure_neumann_system,
        )

        w = node_weights(mesh) if element == "P1" else problem.weights()
        F_sk = check_compatibility(F_sk, weights=w, rtol=case.spec.boundary.compatibility_rtol)[0]
        nodes, values = np.array([0]), np.array([0.0])

        def at_mean_zero(v):
            return v - float(w @ v) / float(w.sum())

        u = at_mean_zero(u)
    else:
        nodes, values = problem.dirichlet_data()
    u_sk = reference.solve_direct(K_sk, F_sk, nodes, values)
    if pure:
        u_sk = at_mean_zero(u_sk)
    rows.append(CheckRow("solution vs scikit-fem" + (" (mean zero)" if pure else ""),
                         _rel(u, u_sk), sol_tol,
                         f"femkit {res.method}+{res.preconditioner}, {res.iterations} it; "
                         "skfem condense + direct"))

    import pyamg

    spd = system
    if getattr(system, "bordered", False):  # indefinite: pyamg gets the pinned SPD system
        spd = pure_neumann_system(K, system.b[:-1], mode="mean_zero", weights=w, method="pcg")
    ml = pyamg.smoothed_aggregation_solver(spd.A.tocsr())
    pyres: list[float] = []
    x_amg = ml.solve(spd.b, tol=spec.rtol, accel="cg", maxiter=spec.maxiter, residuals=pyres)
    x_amg = spd.expand(np.asarray(x_amg).ravel())
    u_ours = u if pure else res.x
    if not pure:
        x_amg = x_amg[system.free]
    rows.append(CheckRow("solution vs pyamg SA (accel=cg)", _rel(u_ours, x_amg), sol_tol,
                         f"pyamg {max(len(pyres) - 1, 0)} it, femkit {res.iterations} it"))
    return rows


def format_table(rows: list[CheckRow]) -> str:
    """Fixed-width table: quantity, relative difference, tolerance, verdict, detail."""
    width = max(len(r.name) for r in rows)
    lines = [f"{'quantity':<{width}}  {'rel. diff':>10}  {'tolerance':>10}  result  detail"]
    for r in rows:
        lines.append(f"{r.name:<{width}}  {r.difference:10.3e}  {r.tolerance:10.3e}  "
                     f"{'ok' if r.passed else 'FAIL':<6}  {r.detail}")
    n_bad = sum(not r.passed for r in rows)
    lines.append("all within tolerance" if n_bad == 0 else f"{n_bad} check(s) out of tolerance")
    return "\n".join(lines)
