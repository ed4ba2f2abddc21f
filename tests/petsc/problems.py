"""The bundled Poisson cases (cases/poisson_*.yaml) as PoissonProblems on coarser meshes,
shared by the MPI driver and the serial reference computed in the tests.

Each entry: geometry or mesh file, and a function ``(mesh) -> (problem, exact, grad)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femkit.fem import PoissonProblem

ROOT = Path(__file__).resolve().parents[2]
pi = np.pi


def unit_square(mesh):
    prob = PoissonProblem(mesh, 1.0, lambda x, y: 2 * pi**2 * np.sin(pi * x) * np.sin(pi * y),
                          dirichlet=[(["boundary"], 0.0)])
    return prob, (lambda x, y: np.sin(pi * x) * np.sin(pi * y),
                  lambda x, y: (pi * np.cos(pi * x) * np.sin(pi * y), pi * np.sin(pi * x) * np.cos(pi * y)))


def annulus(mesh):
    u = lambda x, y: x**2 - y**2 + np.log(np.hypot(x, y))  # noqa: E731
    prob = PoissonProblem(mesh, 1.0, 0.0, dirichlet=[(["inner", "outer"], u)])
    return prob, (u, lambda x, y: (2 * x + x / (x**2 + y**2), -2 * y + y / (x**2 + y**2)))


def lshape(mesh):
    def u(x, y):
        return np.hypot(x, y) ** (2 / 3) * np.sin(2 / 3 * np.mod(np.arctan2(y, x), 2 * pi))
    return PoissonProblem(mesh, 1.0, 0.0, dirichlet=[(["boundary"], u)]), (u, None)


def high_contrast(mesh):
    prob = PoissonProblem(mesh, {"inclusion": 1e6, "matrix": 1.0}, 1.0,
                          dirichlet=[(["boundary"], 0.0)])
    return prob, (None, None)


def plate_mesh_file(mesh):
    prob = PoissonProblem(mesh, 1.0, 0.0, dirichlet=[(["outer"], lambda x, y: x * y)],
                          neumann=[(["hole"], lambda x, y: -(y * (x - 1) + x * (y - 0.5)) / 0.25)])
    return prob, (lambda x, y: x * y, lambda x, y: (y, x))


def poisson_neumann(mesh):
    prob = PoissonProblem(mesh, 1.0, lambda x, y: 2 * pi**2 * np.cos(pi * x) * np.cos(pi * y),
                          dirichlet=[], neumann=[(["boundary"], 0.0)], nullspace="mean_zero")
    return prob, (lambda x, y: np.cos(pi * x) * np.cos(pi * y), None)


def unit_square_p2(mesh):
    prob, exact = unit_square(mesh)
    return PoissonProblem(mesh, prob.kappa, prob.f, dirichlet=prob.dirichlet, element="P2"), exact


def plate_p2(mesh):
    prob, exact = plate_mesh_file(mesh)
    return PoissonProblem(mesh, 1.0, 0.0, dirichlet=prob.dirichlet, neumann=prob.neumann,
                          element="P2"), exact


def neumann_p2(mesh):
    prob, exact = poisson_neumann(mesh)
    return PoissonProblem(mesh, 1.0, prob.f, dirichlet=[], neumann=prob.neumann,
                          nullspace="mean_zero", element="P2"), exact


def cube_p2(mesh):
    """3D P2, Dirichlet on the whole (topological) boundary: u = sin(x) e^y + z^2 (-lap u = -2)."""
    u = lambda x, y, z: np.sin(x) * np.exp(y) + z * z  # noqa: E731
    prob = PoissonProblem(mesh, 1.0, -2.0, dirichlet=[(None, u)], element="P2")
    return prob, (u, lambda x, y, z: (np.cos(x) * np.exp(y), np.sin(x) * np.exp(y), 2 * z))


#: name -> (mesh recipe, problem builder); mesh recipe: ("generate", geometry, h, params),
#: ("file", path) or ("box", n) (femkit's structured n^3 Kuhn cube)
CASES = {
    "unit_square": (("generate", "unit_square", 0.1, {}), unit_square),
    "annulus": (("generate", "annulus", 0.12, {"r_inner": 0.5, "r_outer": 1.0}), annulus),
    "lshape": (("generate", "l_shape", 0.15, {}), lshape),
    "high_contrast": (("generate", "square_with_inclusion", 0.08, {"radius": 0.25}), high_contrast),
    "plate_mesh_file": (("file", str(ROOT / "meshes" / "plate_with_hole.msh")), plate_mesh_file),
    "poisson_neumann": (("generate", "unit_square", 0.1, {}), poisson_neumann),
    "unit_square_p2": (("generate", "unit_square", 0.1, {}), unit_square_p2),
    "plate_p2": (("file", str(ROOT / "meshes" / "plate_with_hole.msh")), plate_p2),
    "neumann_p2": (("generate", "unit_square", 0.15, {}), neumann_p2),
    "cube_p2": (("box", 3), cube_p2),
}


def make_mesh(name: str):
    recipe = CASES[name][0]
    if recipe[0] == "box":
        from femkit.mesh import structured_box

        return structured_box(recipe[1], recipe[1], recipe[1])
    if recipe[0] == "file":
        from femkit.mesh import read_mesh

        return read_mesh(recipe[1])
    from femkit.mesh import generate

    return generate(recipe[1], recipe[2], **recipe[3])


def mesh_arrays(mesh) -> dict:
    """The mesh as plain arrays (saved by the driver, rebuilt by the test)."""
    import json

    return {"points": mesh.points, "cells": mesh.cells, "cell_tags": mesh.cell_tags,
            "boundary_facets": mesh.boundary_facets, "boundary_tags": mesh.boundary_tags,
            "tag_names": json.dumps(mesh.tag_names)}


def mesh_from_arrays(d):
    import json

    from femkit.mesh import Mesh

    return Mesh(d["points"], d["cells"], d["cell_tags"], d["boundary_facets"],
                d["boundary_tags"], json.loads(str(d["tag_names"])))
