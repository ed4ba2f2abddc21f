"""Edges are int32 where the ids fit and int64 beyond: the compiled kernel writes the types it
is given, the same ids either way, and pairs are looked up in int64 (no overflow of
``lo * n + hi`` on 32-bit ids)."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.mesh import Mesh, refine, structured_mesh
from femkit.mesh._edges_kernel import cell_edges
from femkit.mesh.edges import edge_ids, edges, index_dtype
from femkit.mesh.mesh import LOCAL_EDGES


def test_index_dtype_is_int32_up_to_its_largest_value():
    top = np.iinfo(np.int32).max
    assert index_dtype(top) is np.int32 and index_dtype(top + 1) is np.int64


@pytest.mark.parametrize("kind", [np.int32, np.int64], ids=["int32", "int64"])
def test_compiled_edges_in_either_type_are_the_same_ids(kind):
    mesh = refine(structured_mesh(5, 4), 1)
    nodes, cell_map = cell_edges(mesh.cells, LOCAL_EDGES[3], mesh.n_points,
                                 np.zeros(0, kind), np.zeros(0, kind))
    ref_nodes, ref_map = edges(mesh)
    assert nodes.dtype == kind and cell_map.dtype == kind
    assert np.array_equal(nodes, ref_nodes) and np.array_equal(cell_map, ref_map)


def test_edge_lookup_does_not_overflow_32_bit_keys():
    """Node ids near 100,000: ``lo * n`` exceeds 2^31 and must be formed in int64."""
    n = 100_000
    pts = np.zeros((n, 2))
    pts[-3:] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    pts[:-3, 0] = np.linspace(2, 3, n - 3)                 # unused nodes: only ids matter here
    mesh = Mesh(pts, np.array([[n - 3, n - 2, n - 1]]))
    edge_nodes, _ = edges(mesh)
    assert edge_nodes.dtype == np.int32
    got = edge_ids(mesh, edge_nodes, np.array([[n - 1, n - 2], [n - 3, n - 1], [n - 2, n - 3]]))
    assert got.tolist() == [2, 1, 0]
