"""The one-off stiffness from a mesh's known edges (``_edge_values`` / ``_edge_matrix``: no
incidence list, no sort) is the incidence-row matrix bit for bit, on triangles and tetrahedra
whose node and element numbers are scrambled, with a scalar or a per-element coefficient."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError
from femkit.fem import assemble_stiffness
from femkit.fem._one_off_stiffness import stiffness_rows_kernel
from femkit.mesh import Mesh, refine
from femkit.mesh.edges import edges, forget_edges, known_edges

from ._tets import scrambled_box
from .test_kernels import _scrambled as _scrambled_square


def _both_routes(mesh, kappa):
    forget_edges(mesh)
    rows = stiffness_rows_kernel(mesh, kappa)          # incidence rows (edges unknown)
    assert known_edges(mesh) is None
    edges(mesh)
    from_edges = stiffness_rows_kernel(mesh, kappa)    # the edges are known now
    return rows, from_edges


@pytest.mark.parametrize("kappa", ["scalar", "per-element"])
@pytest.mark.parametrize("cells", ["triangles", "tetrahedra", "refined-triangles"])
def test_from_edges_is_the_incidence_matrix_bit_for_bit(make_square, cells, kappa):
    if cells == "triangles":
        mesh = _scrambled_square(make_square)
    elif cells == "tetrahedra":
        mesh = scrambled_box()
    else:
        mesh = refine(_scrambled_square(make_square, draw=5), 2)
    kap = 2.5 if kappa == "scalar" else np.linspace(1.0, 3.0, mesh.n_cells)
    rows, from_edges = _both_routes(mesh, kap)
    for a, b in zip(rows, from_edges):
        assert np.array_equal(a, b)
    # the column and value types of the incidence rows; the row starts already of the
    # columns' type (the matrix's, with no copy)
    assert [a.dtype for a in from_edges] == [rows[1].dtype, rows[1].dtype, rows[2].dtype]


def test_from_edges_a_node_in_no_cell_has_an_empty_row(make_square):
    base = make_square(4)
    pts = np.vstack([base.points[:7], [[5.0, 5.0]], base.points[7:]])
    mesh = Mesh(pts, np.where(base.triangles >= 7, base.triangles + 1, base.triangles))
    rows, from_edges = _both_routes(mesh, 1.0)
    assert from_edges[0][8] == from_edges[0][7]        # row 7: no entry, not even a diagonal
    for a, b in zip(rows, from_edges):
        assert np.array_equal(a, b)


def test_from_edges_names_a_degenerate_triangle():
    mesh = Mesh(np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float), [[0, 1, 2], [0, 1, 3]])
    edges(mesh)
    assert stiffness_rows_kernel(mesh, 1.0) is None     # the caller's pass names the cell
    with pytest.raises(DegenerateMeshError) as info:
        assemble_stiffness(mesh, backend="numba", keep_pattern=False)
    assert info.value.element_ids == [1]
