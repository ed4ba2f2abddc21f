"""The pipeline's assembled systems are symmetric bit for bit, which is why it tells fmg not to
check the finest matrix's symmetry: entry (i, j) and (j, i) sum the same products in the same
element order, on every assembly path (NumPy, compiled row-wise, tetrahedra) and after the
Dirichlet elimination."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import femkit
from femkit.case.poisson.problem import build_mesh_levels, multigrid_inputs, poisson_problem
from femkit.fem import PoissonProblem
from femkit.mesh import Mesh, generate, structured_box

stiffness_module = importlib.import_module("femkit.fem.p1_stiffness")


def _wobbled_box():
    m = structured_box(4, 3, 3)
    p = m.points + 0.03 * np.sin(7 * m.points[:, ::-1]) * m.points * (1 - m.points)
    return Mesh(p, m.cells, boundary_facets=m.boundary_facets, boundary_tags=m.boundary_tags,
                tag_names=m.tag_names)


@pytest.mark.parametrize("mesh, threshold", [
    pytest.param(lambda: generate("l_shape", 0.1), 10 ** 12, id="triangles-numpy"),
    pytest.param(lambda: generate("l_shape", 0.1), 0, id="triangles-compiled-rows"),
    pytest.param(_wobbled_box, 10 ** 12, id="tetrahedra-numpy"),
    pytest.param(_wobbled_box, 0, id="tetrahedra-compiled")])
def test_assembled_and_reduced_systems_are_exactly_symmetric(mesh, threshold, monkeypatch):
    monkeypatch.setattr(stiffness_module, "NUMBA_THRESHOLD", threshold)
    m = mesh()
    kappa = 1.0 + np.arange(m.n_cells) % 7 * np.pi   # varied per element: no cancellation
    problem = PoissonProblem(m, kappa=kappa, f=lambda *x: np.ones_like(x[0]),
                             dirichlet=[(["boundary"], 0.0)])
    K, F = problem.assemble_matrices(keep_pattern=False)
    assert (K != K.T).nnz == 0
    system = problem.reduce(K, F, "fmg", overwrite=True)
    assert system.A.shape[0] < m.n_points and (system.A != system.A.T).nnz == 0


def test_the_pipeline_tells_fmg_alone_to_skip_the_check(base_case, write_case):
    d = dict(base_case, mesh={"geometry": "unit_square", "h": 0.5, "refine": 2},
             solver={"method": "fmg"})
    case = femkit.load_case(write_case(d))
    mesh, hierarchy = build_mesh_levels(case)
    problem = poisson_problem(case, mesh)
    system = problem.assemble("fmg")
    assert multigrid_inputs(case, hierarchy, system)["options"]["check_symmetry"] is False
    d["solver"] = {"method": "pcg", "preconditioner": "gmg"}
    case = femkit.load_case(write_case(d, "gmg.yaml"))
    mg = multigrid_inputs(case, hierarchy, system)
    assert "check_symmetry" not in mg.get("options", {}) and "preconditioner_options" in mg
