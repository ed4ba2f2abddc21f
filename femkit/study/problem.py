"""The Poisson problem of a study: an inline ``problem:`` block or a ``base_case:`` file.

Both are turned into one small adapter with the pieces a sweep needs per mesh: the coarse mesh,
per-element kappa, the source, Dirichlet nodes/values, the exact solution and its gradient.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import CaseFileError, ExpressionError


@dataclass
class PoissonSpec:
    geometry: str | None
    geometry_params: dict
    kappa: object                 # float, callable or a function mesh -> (m,) array
    source: Callable
    exact: Callable | None
    grad_exact: Callable | None
    dirichlet: Callable           # mesh -> (nodes, values)
    neumann: Callable | None      # mesh -> (n,) extra load, or None
    case: object = None
    mesh_file_mesh: Callable | None = None   # () -> Mesh when the base case reads a file

    def kappa_elements(self, mesh) -> np.ndarray:
        from ..fem.coefficients import element_coefficient

        if callable(self.kappa) and getattr(self.kappa, "_per_mesh", False):
            return self.kappa(mesh)
        return element_coefficient(mesh, self.kappa, name="kappa")

    def base_mesh(self, h: float):
        from ..mesh import generate, validate

        if self.mesh_file_mesh is not None:
            return self.mesh_file_mesh()
        return validate(generate(self.geometry, h, **self.geometry_params))


def _expr(key: str, text, *, check_finite: bool = True):
    from ..case.expressions import compile_expression

    try:
        return compile_expression(text, ("x", "y"), check_finite=check_finite)
    except ExpressionError as exc:
        raise ExpressionError(f"{key}: {exc}") from None


def inline_spec(problem: dict) -> PoissonSpec:
    """Compile an inline ``problem:`` block (expressions through the safe parser)."""
    exact = _expr("problem.exact", problem["exact"])
    grad = None
    if "grad_exact" in problem:
        gx = _expr("problem.grad_exact[0]", problem["grad_exact"][0], check_finite=False)
        gy = _expr("problem.grad_exact[1]", problem["grad_exact"][1], check_finite=False)

        def grad(x, y):
            return gx(x, y), gy(x, y)

    source = _expr("problem.source", problem["source"])
    kappa = problem.get("kappa", 1.0)
    if isinstance(kappa, str):
        kappa = _expr("problem.kappa", kappa)
    g = _expr("problem.dirichlet", problem["dirichlet"]) if "dirichlet" in problem else exact

    def dirichlet(mesh):
        from ..mesh import boundary_nodes

        nodes = boundary_nodes(mesh, None)
        p = mesh.points[nodes]
        return nodes, np.broadcast_to(np.asarray(g(p[:, 0], p[:, 1]), float), nodes.shape)

    return PoissonSpec(problem.get("geometry", "unit_square"), dict(problem.get("geometry_params") or {}),
                       kappa, source, exact, grad, dirichlet, None)


def case_spec(path) -> PoissonSpec:
    """Adapter over a Poisson case file (its mesh geometry, coefficient, source, boundary, exact)."""
    from ..case import load_case
    from ..case import run as crun

    case = load_case(path)
    if case.problem != "poisson":
        raise CaseFileError(f"base_case: {path} is a {case.problem!r} case; a convergence study needs 'poisson'")
    if "exact.u" not in case.functions:
        raise CaseFileError(f"base_case: {path} gives no exact solution; a convergence study needs 'exact'")
    spec_mesh = case.data["mesh"]

    def kappa(mesh):
        return crun.element_kappa(case, mesh)

    kappa._per_mesh = True
    grad = None
    if "exact.grad[0]" in case.functions:
        gx, gy = case.functions["exact.grad[0]"], case.functions["exact.grad[1]"]

        def grad(x, y):
            return gx(x, y), gy(x, y)

    def neumann(mesh):
        from ..fem import assemble_neumann

        out = np.zeros(mesh.n_points)
        for i, bc in enumerate(case.data["boundary"].get("neumann", [])):
            out += assemble_neumann(mesh, bc["tags"], case.functions[f"boundary.neumann[{i}].flux"])
        return out

    file_mesh = None
    if "file" in spec_mesh:
        def file_mesh():
            return crun.build_mesh(case)

    return PoissonSpec(spec_mesh.get("geometry"), dict(spec_mesh.get("params") or {}), kappa,
                       case.functions["source"], case.functions["exact.u"], grad,
                       lambda mesh: crun.dirichlet_data(case, mesh),
                       neumann if case.data["boundary"].get("neumann") else None, case, file_mesh)
