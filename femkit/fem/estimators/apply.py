"""Apply an estimator, by name, to a :class:`~femkit.fem.PoissonProblem` and its solution."""

from __future__ import annotations

import numpy as np

from .base import ESTIMATORS, ErrorEstimate


def problem_data(problem) -> dict:
    """The keyword arguments of an estimator taken from a (solved or assembled) PoissonProblem.

    ``dirichlet_nodes`` are the nodes the problem eliminated as Dirichlet data (none for a pure
    Neumann problem, whose pinned node is not a boundary condition).
    """
    if problem.nullspace is not None:
        fixed = np.zeros(0, dtype=np.int64)
    else:
        system = problem.system if problem.system is not None else problem.assemble()
        fixed = system.fixed
    return {"kappa": problem.kappa, "f": problem.f, "neumann": list(problem.neumann),
            "dirichlet_nodes": fixed}


def estimate(problem, u: np.ndarray, estimator: str = "residual") -> ErrorEstimate:
    """Error indicators of the solution ``u`` of ``problem`` by the estimator named ``estimator``.

    >>> import numpy as np
    >>> from femkit.mesh import Mesh
    >>> from femkit.fem import PoissonProblem
    >>> pts = np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.], [.5, .5]])
    >>> tri = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    >>> prob = PoissonProblem(Mesh(pts, tri), f=0.0, dirichlet=[(None, lambda x, y: x + y)])
    >>> u, _ = prob.solve()
    >>> estimate(prob, u, "residual").energy, estimate(prob, u, "zz").energy   # u_h = u exactly
    (0.0, 0.0)
    """
    element = getattr(problem, "element", None)
    if element is not None and element.name != "P1":
        return _higher_order(problem, u, estimator)
    return ESTIMATORS.get(estimator)(problem.mesh, u, **problem_data(problem))


def _higher_order(problem, u: np.ndarray, estimator: str) -> ErrorEstimate:
    """The estimators of a P2 solution: ``residual`` (:mod:`.residual_p2`); any other registered
    name is an InputError naming the one that applies."""
    from ...errors import InputError

    ESTIMATORS.get(estimator)  # an unknown name: the registry's message
    if estimator != "residual":
        raise InputError(f"estimator {estimator!r} is not available for element "
                         f"{problem.element.name}; valid: residual")
    from .residual_p2 import residual_estimator_p2

    return residual_estimator_p2(problem.mesh, u, **problem_data(problem))
