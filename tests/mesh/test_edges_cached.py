"""Edges are computed once per mesh, and the compiled kernel of large meshes finds exactly the
edges (same order, same element -> edge map) that ``np.unique`` finds on small ones."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from femkit.mesh import Mesh, structured_mesh
from femkit.mesh.edges import edges

edges_module = importlib.import_module("femkit.mesh.edges")


def _scrambled_square(n=12, draw=3):
    base = structured_mesh(n, n)
    rng = np.random.default_rng(draw)
    perm = rng.permutation(base.n_points)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    return Mesh(base.points[perm], inv[base.triangles][rng.permutation(base.n_triangles)])


def _box():
    from femkit.mesh import structured_box

    return structured_box(3, 4, 2)


MESHES = {"scrambled-square": _scrambled_square, "box-tetrahedra": _box}


def _by_unique(mesh):
    """The definition: np.unique of the sorted node pairs of every local edge."""
    from femkit.mesh.mesh import LOCAL_EDGES

    loc = mesh.cells[:, LOCAL_EDGES[mesh.cells.shape[1]]].reshape(-1, 2)
    pairs, inverse = np.unique(np.sort(loc, axis=1), axis=0, return_inverse=True)
    return pairs, inverse.reshape(mesh.n_cells, -1)


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("threshold", [0, 10 ** 9], ids=["compiled", "numpy"])
def test_edges_match_the_definition(monkeypatch, name, threshold):
    monkeypatch.setattr(edges_module, "NUMBA_THRESHOLD", threshold)
    mesh = MESHES[name]()
    got_nodes, got_map = edges(mesh)
    ref_nodes, ref_map = _by_unique(mesh)
    assert np.array_equal(got_nodes, ref_nodes)
    assert np.array_equal(got_map, ref_map)
    assert got_nodes.dtype == np.int32 and got_map.dtype == np.int32  # ids fit: half the memory


def test_edges_are_computed_once_and_read_only(monkeypatch):
    mesh = _scrambled_square()
    calls = []
    real = edges_module._edges
    monkeypatch.setattr(edges_module, "_edges", lambda m: calls.append(1) or real(m))
    first = edges(mesh)
    second = edges(mesh)
    assert len(calls) == 1 and first[0] is second[0]
    with pytest.raises(ValueError):
        first[0][0, 0] = 5
    edges(Mesh(mesh.points, mesh.cells))  # another record with the same arrays: its own entry
    assert len(calls) == 2
