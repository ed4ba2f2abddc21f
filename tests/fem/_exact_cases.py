"""The bundled Poisson cases with an exact solution (cases/*.yaml with ``exact:``), built through the
library API: mesh, kappa, f, boundary data, exact u and grad u. Each builder takes the mesh size h.

The data are those of the case files (unit_square, lshape, annulus, poisson_neumann, plate_mesh_file,
fmg_unit_square);
tests/fem/test_estimators.py checks that every case file with ``exact:`` has a builder here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femkit.fem import PoissonProblem
from femkit.mesh import generate, read_mesh, refine

ROOT = Path(__file__).resolve().parents[2]
pi = np.pi


def _theta(x, y):
    return np.mod(np.arctan2(y, x), 2 * pi)


def lshape_u(x, y):
    return np.hypot(x, y) ** (2 / 3) * np.sin(2 / 3 * _theta(x, y))


def lshape_grad(x, y):
    r, t = np.hypot(x, y), _theta(x, y)
    with np.errstate(divide="ignore"):
        c = 2 / 3 * r ** (-1 / 3)
    return -c * np.sin(t / 3), c * np.cos(t / 3)


def unit_square(h):
    prob = PoissonProblem(generate("unit_square", h), 1.0,
                          lambda x, y: 2 * pi ** 2 * np.sin(pi * x) * np.sin(pi * y),
                          dirichlet=[(["boundary"], 0.0)])
    return prob, lambda x, y: (pi * np.cos(pi * x) * np.sin(pi * y), pi * np.sin(pi * x) * np.cos(pi * y))


def lshape(h):
    return PoissonProblem(generate("l_shape", h), 1.0, 0.0, dirichlet=[(["boundary"], lshape_u)]), \
        lshape_grad


def annulus(h):
    u = lambda x, y: x ** 2 - y ** 2 + np.log(np.hypot(x, y))  # noqa: E731
    prob = PoissonProblem(generate("annulus", h, r_inner=0.5, r_outer=1.0), 1.0, 0.0,
                          dirichlet=[(["inner", "outer"], u)])
    return prob, lambda x, y: (2 * x + x / (x * x + y * y), -2 * y + y / (x * x + y * y))


def poisson_neumann(h):
    prob = PoissonProblem(generate("unit_square", h), 1.0,
                          lambda x, y: 2 * pi ** 2 * np.cos(pi * x) * np.cos(pi * y),
                          dirichlet=[], neumann=[(["boundary"], 0.0)], nullspace="mean_zero")
    return prob, lambda x, y: (-pi * np.sin(pi * x) * np.cos(pi * y), -pi * np.cos(pi * x) * np.sin(pi * y))


def plate_mesh_file(h):
    """The .msh file has one size; h = 0.1 / 0.05 / 0.025 map to 0 / 1 / 2 uniform refinements."""
    levels = {0.1: 0, 0.05: 1, 0.025: 2}[h]
    mesh = refine(read_mesh(ROOT / "meshes" / "plate_with_hole.msh"), levels)
    prob = PoissonProblem(mesh, 1.0, 0.0, dirichlet=[(["outer"], lambda x, y: x * y)],
                          neumann=[(["hole"], lambda x, y: -(y * (x - 1) + x * (y - 0.5)) / 0.25)])
    return prob, lambda x, y: (y, x)


CASES = {"unit_square": unit_square, "lshape": lshape, "annulus": annulus,
         "poisson_neumann": poisson_neumann, "plate_mesh_file": plate_mesh_file,
         # cases/poisson_fmg_unit_square.yaml: the unit square's problem, solved by fmg on a
         # refined mesh (the solver and the mesh levels differ, not the data)
         "fmg_unit_square": unit_square}
