"""The duplicate-node check of ``validate`` finds by sorting exactly the pairs scipy's k-d tree
finds (``cKDTree.query_pairs``, the check's former implementation), and a field name with XML's
special characters survives a VTU file (written without ``xml.sax``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from femkit.mesh.validate import _duplicate_pairs
from femkit.mesh.vtk import vtu_header, write_cells


def _tree_pairs(points: np.ndarray, rel_tol: float) -> np.ndarray:
    span = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    pairs = cKDTree(points).query_pairs(rel_tol * (span if span > 0 else 1.0), output_type="ndarray")
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))] if len(pairs) else pairs.reshape(0, 2)


@pytest.mark.parametrize("n, d, rel_tol", [
    (12, 2, 1e-12), (2000, 2, 1e-3), (4000, 3, 2e-2), (20000, 2, 1e-2), (30, 3, 0.5),
], ids=["few-2d", "sparse-2d", "clusters-3d", "dense-2d", "most-pairs-3d"])
def test_same_pairs_as_the_k_d_tree(n, d, rel_tol):
    rng = np.random.default_rng(n + d)
    points = rng.random((n, d))
    points[rng.integers(0, n, 6)] = points[rng.integers(0, n, 6)]  # exact duplicates
    ours, tree = _duplicate_pairs(points, rel_tol), _tree_pairs(points, rel_tol)
    assert len(tree) > 0 and np.array_equal(ours, tree)


def test_grid_points_on_cell_boundaries_and_one_duplicate():
    """A structured grid (many equal coordinates, spacing a multiple of the search cells) with
    one node repeated: the one pair, nothing else."""
    g = np.stack(np.meshgrid(np.linspace(0, 1, 101), np.linspace(0, 2, 51)), -1).reshape(-1, 2)
    points = np.vstack([g, g[[1234]]])
    assert _duplicate_pairs(points, 1e-12).tolist() == [[1234, len(g)]]
    assert _duplicate_pairs(g, 1e-12).shape == (0, 2)
    assert _duplicate_pairs(g, 0.0101 / np.hypot(1, 2)).tolist() == _tree_pairs(g, 0.0101 / np.hypot(1, 2)).tolist()


def test_a_field_name_with_xml_special_characters_reads_back(tmp_path):
    name = 'u & v <x> "q"'  # a double quote alone: quoteattr left it raw (broken XML)
    path = write_cells(tmp_path / "m.vtu", np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                       [("triangle", np.array([[0, 1, 2]]))], point_data={name: np.arange(3.0)})
    names = [a.attrib["Name"] for a in vtu_header(path).iter("DataArray")]
    assert name in names
