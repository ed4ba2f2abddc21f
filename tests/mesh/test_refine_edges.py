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


def _wobbled_box():
    from .test_compiled_mesh_passes import _wobbled_box as box

    return box(3)


@pytest.mark.parametrize(("name", "renumber"), [
    ("gmsh-l-shape", "none"), ("gmsh-l-shape", "rcm"), ("scrambled", "none"),
    ("scrambled", "rcm"), ("kuhn-cube", "rcm"), ("wobbled-box", "rcm"), ("fichera", "rcm")])
def test_every_level_of_a_hierarchy_knows_the_searched_edges(monkeypatch, name, renumber):
    """Each fine level's edges come from the refinement (in the interleaved numbering when the
    hierarchy is renumbered: triangles and tetrahedra): the search finds the same arrays, and
    only the coarsest level is searched. (A hierarchy drops a level's edges once it is refined:
    the finest of hierarchies of 1, 2 and 3 refinements are checked.)"""
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD", 0)
    monkeypatch.setattr(refine_module, "NUMBA_THRESHOLD_3D", 0)
    searched = []
    real = edges_module._edges
    monkeypatch.setattr(edges_module, "_edges", lambda m: searched.append(m.n_cells) or real(m))
    make = {**MESHES, "kuhn-cube": lambda: generate("kuhn_cube", 0.5), "wobbled-box": _wobbled_box,
            "fichera": lambda: generate("kuhn_fichera", 1.0)}[name]
    for levels in (1, 2, 3):
        searched.clear()
        H = MeshHierarchy.from_refinement(make(), levels, renumber=renumber)
        assert searched == [H.coarsest.n_cells]
        derived = edges_module._CACHE[H.finest]
        for a, b, c in zip(derived, real(H.finest), _by_unique(H.finest)):
            assert a.dtype == b.dtype and a.shape == b.shape
            assert np.array_equal(a, b) and np.array_equal(a, c)
            assert not a.flags.writeable
