"""The element abstraction (femkit.elements) against scikit-fem's own elements, and the P2 dof map.

scikit-fem's ``ElementTriP1/P2`` and ``ElementTetP1/P2`` (``lbasis``) give the reference basis
values and gradients; femkit's must equal them at random points to rounding, in the same local
order (vertices, then edges (0,1), (1,2), (0,2) [, (0,3), (1,3), (2,3)]).
"""

from __future__ import annotations

import numpy as np
import pytest
import skfem

from femkit.elements import ELEMENTS, get_element
from femkit.errors import UnknownNameError
from femkit.fem.dofs import dof_map
from femkit.mesh import generate, refine, structured_box

PEERS = {("P1", 2): skfem.ElementTriP1, ("P2", 2): skfem.ElementTriP2,
         ("P1", 3): skfem.ElementTetP1, ("P2", 3): skfem.ElementTetP2}


def _random_points(dim, q=7, state=0):
    lam = np.random.default_rng(state).dirichlet(np.ones(dim + 1), size=q)
    return lam


@pytest.mark.parametrize("name, dim", sorted(PEERS))
def test_basis_and_gradients_equal_scikit_fem(name, dim):
    elem, peer = get_element(name, dim), PEERS[(name, dim)]()
    lam = _random_points(dim)
    X = lam[:, 1:].T                                     # scikit-fem's reference coordinates
    phi, dphi = elem.basis(lam), elem.gradients(lam)
    assert phi.shape == (len(lam), elem.n_dofs) and dphi.shape == (len(lam), elem.n_dofs, dim)
    for i in range(elem.n_dofs):
        ref_phi, ref_dphi = peer.lbasis(X, i)
        np.testing.assert_allclose(phi[:, i], ref_phi, atol=1e-14)
        np.testing.assert_allclose(dphi[:, i].T, ref_dphi, atol=1e-13)


@pytest.mark.parametrize("name, dim", sorted(PEERS))
def test_nodal_basis_partition_of_unity_and_layout(name, dim):
    elem = get_element(name, dim)
    np.testing.assert_allclose(elem.basis(elem.dof_points), np.eye(elem.n_dofs), atol=1e-15)
    np.testing.assert_allclose(elem.basis(_random_points(dim)).sum(axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(elem.gradients(_random_points(dim)).sum(axis=1), 0.0, atol=1e-13)
    edges = {2: 3, 3: 6}[dim]
    assert elem.n_dofs == (dim + 1) + (edges if name == "P2" else 0)
    assert (elem.mass_degree, elem.stiffness_degree) == ((2, 0) if name == "P1" else (4, 2))


@pytest.mark.parametrize("bad", ["P3", "p2x", "p2", ""])
def test_unknown_element_lists_the_valid_ones(bad):
    with pytest.raises(UnknownNameError) as err:
        get_element(bad, 2)
    assert str(err.value) == f"unknown element {bad!r}; valid elements: {', '.join(ELEMENTS.names())}"
    assert ELEMENTS.names() == ["P1", "P2"]


@pytest.mark.parametrize("mesh", [refine(generate("unit_square", 0.5), 1), structured_box(2, 2, 2)],
                         ids=["triangles", "tetrahedra"])
def test_p2_dof_map_numbers_each_edge_once_at_its_midpoint(mesh):
    dm = dof_map(mesh, "P2")
    elem = dm.element
    n_edges = len({tuple(sorted(p)) for c in mesh.cells for p in c[elem.local_edges].tolist()})
    assert dm.n_dofs == mesh.n_points + n_edges and dm.cells.shape == (mesh.n_cells, elem.n_dofs)
    assert (dm.cells[:, :mesh.dim + 1] == mesh.cells).all()
    # edge dof k of a cell sits at the midpoint of that cell's local edge k (so neighbours share it)
    pts = dm.points(mesh)
    mids = 0.5 * (mesh.points[mesh.cells[:, elem.local_edges[:, 0]]]
                  + mesh.points[mesh.cells[:, elem.local_edges[:, 1]]])
    np.testing.assert_array_equal(pts[dm.cells[:, mesh.dim + 1:]], mids)
    assert len(np.unique(pts.round(12), axis=0)) == dm.n_dofs      # one dof per point
    assert np.bincount(dm.cells.ravel(), minlength=dm.n_dofs).min() >= 1
    # deterministic: a copy of the mesh gets the same numbering
    from femkit.mesh import Mesh

    again = dof_map(Mesh(mesh.points.copy(), mesh.cells.copy()), "P2")
    np.testing.assert_array_equal(again.cells, dm.cells)
