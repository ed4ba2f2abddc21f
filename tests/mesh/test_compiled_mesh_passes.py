"""The compiled passes of the mesh stage (red refinement, quality numbers, the hierarchy's
interleaved numbering) give what their NumPy definitions give: refined meshes and hierarchies
array for array, quality numbers to round-off."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from femkit.mesh import Mesh, MeshHierarchy, generate, refine, structured_mesh
from femkit.mesh.edges import edges

refine_module = importlib.import_module("femkit.mesh.refine")
quality_module = importlib.import_module("femkit.mesh.quality")
edges_module = importlib.import_module("femkit.mesh.edges")

MESH_ARRAYS = ("points", "cells", "cell_tags", "boundary_facets", "boundary_tags")


def _tagged_skewed(n=9, draw=5):
    """A structured square with wobbled interior nodes, two cell tags, a tagged boundary and
    its nodes and triangles in random order (no structure the kernels could lean on)."""
    base = structured_mesh(n, n)
    rng = np.random.default_rng(draw)
    pts = base.points + 0.02 * np.sin(5 * base.points[:, ::-1]) * (base.points * (1 - base.points))
    perm = rng.permutation(base.n_points)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    order = rng.permutation(base.n_cells)
    tags = np.where(base.centroids()[:, 0] < 0.5, 1, 2)[order]
    return Mesh(pts[perm], inv[base.triangles][order], cell_tags=tags,
                boundary_facets=inv[base.boundary_facets], boundary_tags=base.boundary_tags,
                tag_names=dict(base.tag_names))


def _numpy_paths(monkeypatch):
    for mod in (refine_module, quality_module, edges_module):
        monkeypatch.setattr(mod, "NUMBA_THRESHOLD", 10 ** 12)
    for mod in (refine_module, quality_module):
        monkeypatch.setattr(mod, "NUMBA_THRESHOLD_3D", 10 ** 12)


def _compiled_paths(monkeypatch):
    for mod in (refine_module, quality_module, edges_module):
        monkeypatch.setattr(mod, "NUMBA_THRESHOLD", 0)
    for mod in (refine_module, quality_module):
        monkeypatch.setattr(mod, "NUMBA_THRESHOLD_3D", 0)


def _wobbled_box(n=4, draw=7):
    """A Kuhn box with moved interior nodes, its nodes and tetrahedra in random order and two
    cell tags: shortest diagonals without ties, and ties (the untouched boundary layer)."""
    box = generate("kuhn_cube", 1.0 / n)
    rng = np.random.default_rng(draw)
    pts = box.points.copy()
    inside = np.all((pts > 1e-9) & (pts < 1 - 1e-9), axis=1)
    pts[inside] += 0.3 / n * (rng.random((inside.sum(), 3)) - 0.5)
    perm = rng.permutation(box.n_points)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    order = rng.permutation(box.n_cells)
    tags = np.where(box.centroids()[order, 2] < 0.5, 1, 2)
    return Mesh(pts[perm], inv[box.cells][order], cell_tags=tags,
                boundary_facets=inv[box.boundary_facets], boundary_tags=box.boundary_tags,
                tag_names=dict(box.tag_names))


def _flat_one():
    """:func:`_wobbled_box` with one flat tetrahedron (a repeated vertex): NaN dihedral angles,
    radius ratio 0, diagonals of length 0."""
    m = _wobbled_box(3)
    cells = m.cells.copy()
    cells[0, 3] = cells[0, 2]
    return Mesh(m.points, cells)


TET_MESHES = {"kuhn-cube": lambda: generate("kuhn_cube", 1 / 3), "wobbled": _wobbled_box,
              "fichera": lambda: generate("kuhn_fichera", 0.5), "one-flat": _flat_one}


@pytest.mark.parametrize("name", sorted(TET_MESHES))
def test_compiled_tetrahedral_refinement_is_the_numpy_refinement(monkeypatch, name):
    mesh = TET_MESHES[name]()
    _numpy_paths(monkeypatch)
    ref = refine(mesh, 2)
    _compiled_paths(monkeypatch)
    got = refine(Mesh(mesh.points, mesh.cells, mesh.cell_tags, mesh.boundary_facets,
                      mesh.boundary_tags, mesh.tag_names), 2)
    for name in MESH_ARRAYS:
        a, b = getattr(got, name), getattr(ref, name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name


def _both_qualities(monkeypatch, mesh):
    """``quality(mesh)`` by the NumPy formulas and by the compiled pass (a fresh mesh record,
    so nothing cached is shared)."""
    _numpy_paths(monkeypatch)
    ref = quality_module.quality(mesh)
    _compiled_paths(monkeypatch)
    got = quality_module.quality(Mesh(mesh.points, mesh.cells))
    assert got.keys() == ref.keys()
    return ref, got


@pytest.mark.parametrize("name", sorted(TET_MESHES))
def test_compiled_tetrahedral_quality_is_the_numpy_quality_bit_for_bit(monkeypatch, name):
    """The same floats (result.json's mesh numbers do not move), NaN angles skipped alike."""
    ref, got = _both_qualities(monkeypatch, refine(TET_MESHES[name](), 1))
    for k in ref:
        assert np.array_equal(got[k], ref[k], equal_nan=True), (k, got[k], ref[k])


@pytest.mark.parametrize("levels", [1, 3], ids=["one-level", "three-levels"])
def test_compiled_refinement_is_the_numpy_refinement(monkeypatch, levels):
    mesh = _tagged_skewed()
    _numpy_paths(monkeypatch)
    ref = refine(mesh, levels)
    _compiled_paths(monkeypatch)
    got = refine(Mesh(mesh.points, mesh.cells, mesh.cell_tags, mesh.boundary_facets,
                      mesh.boundary_tags, mesh.tag_names), levels)
    for name in MESH_ARRAYS:
        a, b = getattr(got, name), getattr(ref, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name


@pytest.mark.parametrize("renumber", ["none", "rcm"])
@pytest.mark.parametrize("dim", [2, 3], ids=["triangles", "tetrahedra"])
def test_compiled_hierarchy_is_the_numpy_hierarchy(monkeypatch, renumber, dim):
    """Renumbered, the compiled path refines straight into the interleaved numbering (and
    builds the prolongation's rows in it): the NumPy path refines, then permutes."""
    mesh = _tagged_skewed(7) if dim == 2 else _wobbled_box(3)
    _numpy_paths(monkeypatch)
    ref = MeshHierarchy.from_refinement(mesh, 2, renumber=renumber)
    _compiled_paths(monkeypatch)
    got = MeshHierarchy.from_refinement(Mesh(mesh.points, mesh.cells, mesh.cell_tags,
                                             mesh.boundary_facets, mesh.boundary_tags,
                                             mesh.tag_names), 2, renumber=renumber)
    for a, b in zip(got.meshes, ref.meshes):
        for name in MESH_ARRAYS:
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for P, Q in zip(got.prolongations, ref.prolongations):
        assert (P != Q).nnz == 0 and P.shape == Q.shape
        assert np.array_equal(P.indptr, Q.indptr) and np.array_equal(P.indices, Q.indices)
    for a, b in zip(got.injections, ref.injections):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("compiled", [False, True], ids=["numpy", "compiled"])
def test_injections_hold_no_view_of_the_fine_numbering(monkeypatch, compiled):
    """Renumbered, the injection of a level is the start of the finer level's numbering
    ``inv``: taken as the view ``inv[:n_coarse]`` it kept all of ``inv`` (4x the entries in 2D,
    15 MiB at 1.9M fine nodes) alive with the hierarchy. Each is its own array."""
    (_compiled_paths if compiled else _numpy_paths)(monkeypatch)
    H = MeshHierarchy.from_refinement(_tagged_skewed(7), 2, renumber="rcm")
    for lvl, inj in enumerate(H.injections):
        assert inj.base is None and inj.shape == (H.meshes[lvl].n_points,)


def test_interleaved_numbering_is_the_stable_merge():
    """The O(n) numbering equals its definition: a stable sort of coarse ids and edge lower nodes."""
    hierarchy = importlib.import_module("femkit.mesh.hierarchy")
    mesh = _tagged_skewed()
    edge_nodes, _ = edges(mesh)
    key = np.concatenate([np.arange(mesh.n_points), edge_nodes[:, 0]])
    assert np.array_equal(hierarchy.interleave_permutation(mesh.n_points, edge_nodes),
                          np.argsort(key, kind="stable"))


def _degenerate_one():
    """A mesh with one zero-area triangle (a repeated vertex): NaN angles, infinite aspect."""
    m = _tagged_skewed(5)
    cells = m.cells.copy()
    cells[0, 2] = cells[0, 1]
    return Mesh(m.points, cells)


@pytest.mark.parametrize("make", [_tagged_skewed, _degenerate_one], ids=["skewed", "degenerate"])
def test_compiled_quality_is_the_numpy_quality(monkeypatch, make):
    ref, got = _both_qualities(monkeypatch, make())
    for k in ref:
        if np.isinf(ref[k]):
            assert got[k] == ref[k], k
        else:
            assert got[k] == pytest.approx(ref[k], rel=1e-13, abs=0), k


def test_hierarchy_keeps_no_edges_of_its_coarser_levels():
    """The coarser levels' edges are needed only while they are refined (memory of a large run)."""
    H = MeshHierarchy.from_refinement(_tagged_skewed(5), 2)
    assert all(m not in edges_module._CACHE for m in H.meshes[:-1])
    assert np.array_equal(edges(H.meshes[0])[0], edges(_tagged_skewed(5))[0])  # recomputed on demand
