"""Quadrature for P2: every registered rule exact to its stated degree on every monomial of the
barycentric coordinates (exact integrals by the Dirichlet formula, not femkit's), the reference
mass and stiffness tables against closed forms, and P2's default load rules."""

from __future__ import annotations

import itertools
from math import factorial

import numpy as np
import pytest

from femkit.elements import get_element
from femkit.fem.forms import reference_mass, reference_stiffness
from femkit.fem.lagrange import load_rule
from femkit.fem.quadrature import QUADRATURE, TET_QUADRATURE, get_rule, rule_for_degree


def _exact(alpha) -> float:
    """(1/|T|) int_T prod lambda_i^alpha_i = d! prod alpha_i! / (|alpha| + d)!."""
    d = len(alpha) - 1
    return factorial(d) * np.prod([factorial(a) for a in alpha]) / factorial(sum(alpha) + d)


@pytest.mark.parametrize("dim, name", [(2, n) for n in QUADRATURE] + [(3, n) for n in TET_QUADRATURE])
def test_rule_is_exact_to_its_degree(dim, name):
    rule = get_rule(name, dim)
    worst = 0.0
    for alpha in itertools.product(range(rule.degree + 1), repeat=dim + 1):
        if sum(alpha) <= rule.degree:
            q = rule.weights @ np.prod(rule.points ** np.array(alpha), axis=1)
            worst = max(worst, abs(q - _exact(alpha)) / _exact(alpha))
    assert worst < 1e-13, worst
    assert rule.weights.min() > 0 and np.allclose(rule.points.sum(axis=1), 1.0, atol=1e-15)


def test_p2_load_rules_and_the_automatic_choice():
    assert [load_rule(get_element("P2", d)).name for d in (2, 3)] == ["gauss6", "sym14"]
    assert rule_for_degree(5, 3).name == "stroud27"        # P1's error norms keep their rule


@pytest.mark.parametrize("dim", [2, 3])
def test_reference_tables_against_closed_forms(dim):
    """P2 mass: vertex-vertex 6/((d+1)(d+2)(d+3)) ... by the monomial formula; the stiffness table
    contracted with any gradients annihilates constants (rows sum to zero)."""
    elem = get_element("P2", dim)
    R = reference_mass(elem)
    nv = dim + 1
    # phi_a phi_a = lambda_a^2 (2 lambda_a - 1)^2 = 4 l^4 - 4 l^3 + l^2
    l_pow = lambda k: _exact(tuple(k if i == 0 else 0 for i in range(nv)))   # noqa: E731
    assert R[0, 0] == pytest.approx(4 * l_pow(4) - 4 * l_pow(3) + l_pow(2), rel=1e-13)
    # edge-edge (0,1): 16 l0^2 l1^2
    assert R[nv, nv] == pytest.approx(16 * _exact((2, 2) + (0,) * (nv - 2)), rel=1e-13)
    assert R.sum() == pytest.approx(1.0, rel=1e-14)
    S = reference_stiffness(elem)
    G = np.random.default_rng(0).standard_normal((nv, dim))
    G[0] = -G[1:].sum(axis=0)                   # barycentric gradients sum to zero
    K = np.einsum("ab,abij->ij", G @ G.T, S)
    np.testing.assert_allclose(K, K.T, atol=1e-13)
    np.testing.assert_allclose(K.sum(axis=1), 0.0, atol=1e-12)     # constants: no energy
    assert np.linalg.eigvalsh(K)[1] > 1e-8                          # only constants
