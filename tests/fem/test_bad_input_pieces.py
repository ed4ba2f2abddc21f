"""Bad input to the FEM building blocks raises InputError naming the problem, never a NaN
or a silently different answer."""

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import InputError
from femkit.fem import apply_dirichlet, error_norms
from femkit.fem.quadrature import rule_for_degree
from femkit.mesh import Mesh

K = sp.csr_matrix(np.array([[2., -1, 0, 0], [-1, 2, -1, 0], [0, -1, 2, -1], [0, 0, -1, 2]]))
F = np.ones(4)


@pytest.mark.parametrize("values", [[0.0, np.nan], [np.inf, 1.0], np.nan],
                         ids=["nan", "inf", "scalar-nan"])
def test_dirichlet_non_finite_values_refused(values):
    with pytest.raises(InputError, match="not finite"):
        apply_dirichlet(K, F, [0, 3], values)


def test_dirichlet_boolean_mask_means_the_marked_nodes():
    mask = np.array([True, False, False, True])
    by_mask = apply_dirichlet(K, F, mask, [1.0, 3.0])
    by_ids = apply_dirichlet(K, F, [0, 3], [1.0, 3.0])
    assert by_mask.fixed.tolist() == [0, 3] and by_mask.free.tolist() == [1, 2]
    np.testing.assert_array_equal(by_mask.b, by_ids.b)


def test_dirichlet_mask_of_wrong_length_refused():
    with pytest.raises(InputError, match="mask"):
        apply_dirichlet(K, F, np.array([True, False, True]), 0.0)


def test_dirichlet_fractional_node_ids_refused():
    with pytest.raises(InputError, match="integer"):
        apply_dirichlet(K, F, np.array([0.5, 3.0]), 0.0)


def test_dirichlet_conflicting_duplicate_nodes_refused():
    assert apply_dirichlet(K, F, [0, 0, 3], [1.0, 1.0, 2.0]).fixed.tolist() == [0, 3]
    with pytest.raises(InputError, match="node 0"):
        apply_dirichlet(K, F, [0, 0, 3], [1.0, 2.0, 2.0])


def test_quadrature_degree_beyond_every_rule_refused():
    assert rule_for_degree(5).degree >= 5
    with pytest.raises(InputError, match="degree 9"):
        rule_for_degree(9)


def test_error_norms_order_beyond_every_rule_refused():
    m = Mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
    with pytest.raises(InputError, match="degree 12"):
        error_norms(m, np.zeros(3), lambda x, y: x**6 * y**6, order=12)
