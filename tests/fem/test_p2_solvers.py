"""Every registered solver and preconditioner on a P2 matrix, multigrid through the p-level
(P2 -> P1 on the same mesh, then the P1 hierarchy): each reaches the direct solution."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.fem import PoissonProblem
from femkit.mesh import MeshHierarchy, generate
from femkit.solvers import solve
from femkit.solvers.registry import PRECONDITIONERS, SOLVERS, traits

HIERARCHY = MeshHierarchy.from_refinement(generate("unit_square", 0.25), 1).with_quadratic_level()
EXACT = lambda x, y: np.sin(np.pi * x) * np.sin(2 * np.pi * y) + x * y          # noqa: E731


def _system():
    prob = PoissonProblem(HIERARCHY.meshes[-2], 1.0, lambda x, y: 5 * np.pi ** 2 * np.sin(np.pi * x) * np.sin(2 * np.pi * y),
                          dirichlet=[(None, EXACT)], element="P2")
    return prob, prob.assemble()


def _runs():
    """(method, preconditioner) for every registered solver and, with pcg, every preconditioner."""
    runs = [(m, None) for m in SOLVERS.names() if m != "pcg"]
    return runs + [("pcg", p) for p in PRECONDITIONERS.names()]


@pytest.mark.parametrize("method, preconditioner", _runs())
def test_every_solver_solves_the_p2_system(method, preconditioner):
    if method == "cholesky":  # an optional backend (scikit-sparse, the cholesky extra)
        pytest.importorskip("sksparse", reason="cholesky needs scikit-sparse: pip install -e '.[cholesky]'")
    prob, system = _system()
    direct = solve(system.A, system.b, method="direct").x
    opts = {}
    mg = {"hierarchy": HIERARCHY, "free": system.free}
    if traits(SOLVERS, method).needs_hierarchy:
        opts = {**mg, "target": "residual"}
    kwargs = {}
    if preconditioner and traits(PRECONDITIONERS, preconditioner).needs_hierarchy:
        kwargs["preconditioner_options"] = mg
    slow = method in ("jacobi", "sd")                 # O(h^-2) iterations: a looser, reachable rtol
    res = solve(system.A, system.b, method=method, preconditioner=preconditioner,
                rtol=1e-6 if slow else 1e-10, maxiter=200_000, **opts, **kwargs)
    assert res.converged, res.message
    err = np.abs(res.x - direct).max() / np.abs(direct).max()
    assert err < (1e-3 if slow else 1e-8)


def test_p_level_galerkin_product_is_the_p1_stiffness():
    """P^T K_P2 P = K_P1 on the same mesh: the p-level's coarse operator is P1's."""
    from femkit.fem import assemble_stiffness
    from femkit.fem.forms import assemble_matrix

    mesh = HIERARCHY.meshes[-2]
    P = HIERARCHY.prolongations[-1]
    K2 = assemble_matrix(mesh, "stiffness", 1.0, element="P2")
    assert abs(P.T @ K2 @ P - assemble_stiffness(mesh)).max() < 1e-12


def test_gmg_through_the_p_level_takes_few_iterations():
    prob, system = _system()
    res = solve(system.A, system.b, method="pcg", preconditioner="gmg", rtol=1e-10,
                preconditioner_options={"hierarchy": HIERARCHY, "free": system.free})
    amg = solve(system.A, system.b, method="pcg", preconditioner="jacobi", rtol=1e-10)
    assert res.converged and res.iterations <= 12 and res.iterations < amg.iterations / 4
