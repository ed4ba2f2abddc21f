"""Red refinement hands the fine mesh its edges derived from the coarse mesh's: exactly the
arrays the edge search finds on the fine mesh (same order, same element -> edge map, same
dtype), so no level of a hierarchy but the coarsest searches its edges."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from femkit.mesh import Mesh, MeshHierarchy, generate, structured_mesh

from .test_edges_cached import _by_unique, _scrambled_square

refine_module = importlib.import_module("femkit.mesh.refine")
edges_module = importlib.import_module("femkit.mesh.edges")


def _with_duplicate():
    """Two squares' triangles, one of them twice: a pair of midpoints shared by two children."""
    m = structured_mesh(2, 2)
    return Mesh(m.points, np.vstack([m.triangles, m.triangles[:1]]))


MESHES = {
    "structured": lambda: structured_mesh(7, 5),
    "scrambled": _scrambled_square,
    "gmsh-l-shape": lambda: generate("l_shape", 0.2),
    "duplicate-triangle": _with_duplicate,
}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_derived_edges_are_the_searched_edges(monkeypatch, name):
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD", 0)     # the compiled refinement
    mesh = MESHES[name]()
    for _ in range(3):
        fine, _ = refine_module.refine_once(mesh)
        derived = edges_module._CACHE[fine]
        searched = edges_module._edges(fine)
        for a, b, c in zip(derived, searched, _by_unique(fine)):
            assert a.dtype == b.dtype and a.shape == b.shape
            assert np.array_equal(a, b) and np.array_equal(a, c)
            assert not a.flags.writeable
        mesh = fine


def test_a_hierarchy_searches_only_its_coarsest_edges(monkeypatch):
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD", 0)
    searched = []
    real = edges_module._edges
    monkeypatch.setattr(edges_module, "_edges", lambda m: searched.append(m.n_cells) or real(m))
    coarse = generate("unit_square", 0.25)
    H = MeshHierarchy.from_refinement(coarse, 3)
    edges_module.edges(H.finest)
    assert searched == [coarse.n_cells]
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD", 10 ** 12)   # the NumPy refinement
    searched.clear()
    H = MeshHierarchy.from_refinement(coarse, 2)
    edges_module.edges(H.finest)
    assert searched == [m.n_cells for m in H.meshes]


def test_a_renumbered_hierarchy_derives_no_edges_it_would_drop(monkeypatch):
    """Renumbering reorders the fine mesh's edges: the derived ones would be thrown away."""
    kernel = importlib.import_module("femkit.mesh._refine_kernel")
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD", 0)
    calls = []
    real = kernel.child_edges
    monkeypatch.setattr(kernel, "child_edges", lambda *a: calls.append(1) or real(*a))
    coarse = generate("unit_square", 0.25)
    H = MeshHierarchy.from_refinement(coarse, 2, renumber="rcm")
    assert calls == [] and all(m not in edges_module._CACHE for m in H.meshes[1:])
    MeshHierarchy.from_refinement(coarse, 2)
    assert calls == [1, 1]
