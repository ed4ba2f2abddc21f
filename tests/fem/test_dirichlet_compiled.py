"""The compiled Dirichlet elimination of large systems gives SciPy's ``K[free][:, free]`` and
``F[free] - K[free] g`` exactly, in place too."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness
from femkit.mesh import boundary_nodes, structured_mesh

dirichlet_module = importlib.import_module("femkit.fem.dirichlet")


def _system():
    mesh = structured_mesh(13, 11)
    K = assemble_stiffness(mesh, 1.0 + mesh.centroids()[:, 0])
    F = assemble_load(mesh, lambda x, y: np.sin(3 * x) + y)
    nodes = boundary_nodes(mesh)
    return K, F, nodes, np.cos(mesh.points[nodes, 0]) + 2.0


@pytest.mark.parametrize("overwrite", [False, True], ids=["copy", "in-place"])
def test_compiled_elimination_is_scipys(monkeypatch, overwrite):
    K, F, nodes, g = _system()
    monkeypatch.setattr(dirichlet_module, "NUMBA_THRESHOLD", 10 ** 12)
    ref = apply_dirichlet(K, F, nodes, g)
    monkeypatch.setattr(dirichlet_module, "NUMBA_THRESHOLD", 0)
    got = apply_dirichlet(K.copy(), F, nodes, g, overwrite=overwrite)
    assert got.A.shape == ref.A.shape and got.A.has_sorted_indices
    assert np.array_equal(got.A.indptr, ref.A.indptr) and np.array_equal(got.A.indices, ref.A.indices)
    assert np.array_equal(got.A.data, ref.A.data)
    assert np.array_equal(got.b, ref.b)
    assert np.array_equal(got.free, ref.free) and np.array_equal(got.fixed, ref.fixed)


def test_without_overwrite_the_matrix_is_untouched(monkeypatch):
    K, F, nodes, g = _system()
    before = K.copy()
    monkeypatch.setattr(dirichlet_module, "NUMBA_THRESHOLD", 0)
    apply_dirichlet(K, F, nodes, g)
    assert (K != before).nnz == 0 and np.array_equal(K.indptr, before.indptr)
