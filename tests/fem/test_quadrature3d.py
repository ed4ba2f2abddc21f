"""Tetrahedron quadrature: exact on monomials up to the stated degree, Gauss-Jacobi vs SciPy."""

import itertools
from math import factorial

import numpy as np
import pytest

from femkit.errors import UnknownNameError
from femkit.fem.quadrature import TET_QUADRATURE, gauss_jacobi, get_rule, rule_for_degree


def _monomials(degree):
    return [(a, b, c) for a, b, c in itertools.product(range(degree + 1), repeat=3) if a + b + c <= degree]


@pytest.mark.parametrize("name", sorted(TET_QUADRATURE.names()))
def test_exact_to_its_degree(name):
    """int over the unit tetrahedron of x^a y^b z^c = a! b! c! / (a + b + c + 3)! (times 6 for
    weights that sum to one)."""
    rule = get_rule(name, dim=3)
    x, y, z = rule.points[:, 1], rule.points[:, 2], rule.points[:, 3]
    for a, b, c in _monomials(rule.degree):
        exact = 6.0 * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3)
        assert rule.weights @ (x ** a * y ** b * z ** c) == pytest.approx(exact, rel=1e-13, abs=1e-15)
    # and not exact one degree higher (the degree is the true one)
    errs = [abs(rule.weights @ (x ** a * y ** b * z ** c)
                - 6.0 * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3))
            for a, b, c in _monomials(rule.degree + 1) if a + b + c == rule.degree + 1]
    assert max(errs) > 1e-8


@pytest.mark.parametrize("n", [1, 2, 3, 4, 6])
@pytest.mark.parametrize("alpha", [0.0, 1.0, 2.0])
def test_gauss_jacobi_equals_scipy(n, alpha):
    from scipy.special import roots_jacobi

    t, w = gauss_jacobi(n, alpha)
    tr, wr = roots_jacobi(n, alpha, 0.0)
    np.testing.assert_allclose(t, tr, atol=1e-14)
    np.testing.assert_allclose(w, wr / wr.sum(), atol=1e-14)


def test_rule_for_degree_in_3d():
    assert rule_for_degree(5, 3).name == "stroud27"
    assert rule_for_degree(2, 3).name == "gauss4"
    with pytest.raises(UnknownNameError, match="gauss4"):
        get_rule("gauss6", dim=3)
