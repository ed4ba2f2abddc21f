"""The compiled 3D passes of the errors and estimate stages agree with the NumPy reference.

* ``faces``: the compiled counting sort gives the very arrays of the lexicographic NumPy sort
  (same numbering) on a mesh with scrambled nodes and elements;
* the residual estimator on tetrahedra: the compiled pass (element fields, face jumps, longest
  edges in one loop) equals the NumPy path to 1e-12 in every part, with a per-region ``kappa``,
  Dirichlet faces, a Neumann face with data and natural faces; a flat tetrahedron still gets
  its one-line error naming it.
"""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError
from femkit.fem import PoissonProblem
from femkit.fem.estimators import ESTIMATORS
from femkit.fem.estimators import residual_faces
from femkit.fem.estimators.apply import problem_data
import importlib
from femkit.mesh import Mesh

from ._tets import grad_exact, perturbed_box, scrambled_box, source

faces_module = importlib.import_module("femkit.mesh.faces")  # the module (the package exports the function)


def test_compiled_faces_are_the_sorted_unique_faces(monkeypatch):
    mesh = scrambled_box()
    ref_nodes, ref_tf = faces_module.faces(mesh)
    monkeypatch.setattr(faces_module, "NUMBA_THRESHOLD", 0)
    nodes, tf = faces_module.faces(mesh)
    assert np.array_equal(nodes, ref_nodes) and np.array_equal(tf, ref_tf)
    assert nodes.dtype == np.int64 and tf.dtype == np.int64


def _estimate(mesh, compiled: bool, monkeypatch):
    monkeypatch.setattr(residual_faces, "NUMBA_THRESHOLD", 0 if compiled else 10**12)
    kappa = {"left_half": 2.0, "right_half": 0.5}
    prob = PoissonProblem(mesh, f=source, kappa=kappa, dirichlet=[("xmin", 0.0), ("ymin", 1.0)],
                          neumann=[("xmax", lambda x, y, z: grad_exact(x, y, z)[0])])
    u = np.sin(mesh.points @ np.array([1.0, 2.0, 0.5]))      # any nodal values: all terms non-zero
    return ESTIMATORS.get("residual")(mesh, u, **problem_data(prob))


def test_compiled_residual_estimator_equals_numpy(monkeypatch):
    mesh = perturbed_box(4, state=8)
    ref = _estimate(mesh, False, monkeypatch)
    got = _estimate(mesh, True, monkeypatch)
    for name, part in ref.parts.items():
        assert np.abs(part).max() > 0, name
        assert np.abs(got.parts[name] - part).max() <= 1e-12 * np.abs(part).max(), name
    assert abs(got.energy - ref.energy) <= 1e-12 * ref.energy


def test_compiled_residual_estimator_names_a_flat_tetrahedron(monkeypatch):
    mesh = perturbed_box(3, state=2)
    pts = mesh.points.copy()
    pts[mesh.cells[5, 3]] = pts[mesh.cells[5, 0]]
    flat = Mesh(pts, mesh.cells, cell_tags=mesh.cell_tags, boundary_facets=mesh.boundary_facets,
                boundary_tags=mesh.boundary_tags, tag_names=mesh.tag_names)
    monkeypatch.setattr(residual_faces, "NUMBA_THRESHOLD", 0)
    with pytest.raises(DegenerateMeshError) as info:
        ESTIMATORS.get("residual")(flat, np.zeros(flat.n_points), f=1.0)
    assert 5 in info.value.element_ids


def test_compiled_error_pass_names_a_flat_tetrahedron(monkeypatch):
    """The fused 3D error pass computes each volume itself: a zero one sends the run to the
    NumPy path, which names the tetrahedron (the same error as without the compiled pass)."""
    from femkit.case.compiled_expressions import expression_kernels
    from femkit.case.expressions import compile_expression
    from femkit.fem import error_norms
    from femkit.fem.fused import kernels as fused_kernels

    mesh = perturbed_box(2, state=4)
    pts = mesh.points.copy()
    pts[mesh.cells[3, 2]] = pts[mesh.cells[3, 1]]
    flat = Mesh(pts, mesh.cells)
    exact = compile_expression("x + y * z", ("x", "y", "z"))
    expression_kernels(exact)
    messages = []
    for threshold in (10 ** 12, 0):
        monkeypatch.setattr(fused_kernels, "NUMBA_THRESHOLD", threshold)
        with pytest.raises(DegenerateMeshError) as info:
            error_norms(flat, np.zeros(flat.n_points), exact)
        messages.append(str(info.value))
        assert 3 in info.value.element_ids
    assert messages[0] == messages[1]
