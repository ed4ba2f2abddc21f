"""Quadrature exactness, coefficient validation, Dirichlet elimination, norms, lean import."""

import math
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from femkit.errors import DegenerateMeshError, InputError, MeshError, UnknownNameError
from femkit.fem import (QUADRATURE, apply_dirichlet, assemble_load, assemble_neumann, assemble_stiffness,
                        dirichlet_values, error_norms, get_rule)
from femkit.mesh import Mesh


def _monomial_integral(i, j):
    """Exact integral of x^i y^j over the reference triangle (0,0), (1,0), (0,1)."""
    return math.factorial(i) * math.factorial(j) / math.factorial(i + j + 2)


@pytest.mark.parametrize("name", sorted(QUADRATURE.names()))
def test_rule_exact_to_its_degree_and_not_beyond(name):
    rule = get_rule(name)
    x, y = rule.points[:, 1], rule.points[:, 2]  # reference triangle: lambda_1 = x, lambda_2 = y
    for deg in range(rule.degree + 1):
        for i in range(deg + 1):
            approx = 0.5 * np.sum(rule.weights * x**i * y ** (deg - i))
            assert approx == pytest.approx(_monomial_integral(i, deg - i), rel=1e-12, abs=1e-15)
    deg = rule.degree + 1
    errs = [abs(0.5 * np.sum(rule.weights * x**i * y ** (deg - i)) - _monomial_integral(i, deg - i))
            for i in range(deg + 1)]
    assert max(errs) > 1e-8  # the stated degree is the true one


def test_unknown_rule_name():
    with pytest.raises(UnknownNameError, match="gauss6"):
        assemble_load(Mesh(np.eye(3)[:, :2], [[0, 1, 2]]), 1.0, rule="gauss99")


@pytest.mark.parametrize("kappa", [0.0, -1.0, np.nan, np.inf], ids=["zero", "negative", "nan", "inf"])
def test_bad_scalar_kappa_raises(square8, kappa):
    with pytest.raises(InputError, match=f"{square8.n_triangles} element"):
        assemble_stiffness(square8, kappa)


def test_bad_kappa_names_first_ids(square8):
    kap = np.ones(square8.n_triangles)
    kap[[5, 17]] = [-2.0, 0.0]
    with pytest.raises(InputError, match=r"2 element\(s\).*\[5, 17\]"):
        assemble_stiffness(square8, kap)
    with pytest.raises(InputError, match="first ids"):
        assemble_stiffness(square8, lambda x, y: x - 0.5)


@pytest.mark.parametrize("kappa", [{1: 1.0}, {"nowhere": 1.0}, np.ones(3), "abc"],
                         ids=["missing-tag", "unknown-name", "wrong-length", "string"])
def test_bad_kappa_tables_and_arrays(square8, kappa):
    with pytest.raises(InputError):
        assemble_stiffness(square8, kappa)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_degenerate_triangle_named(backend):
    mesh = Mesh(np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(DegenerateMeshError) as info:
        assemble_stiffness(mesh, backend=backend)
    assert info.value.element_ids == [1]


def test_dirichlet_elimination_against_dense():
    rng = np.random.default_rng(0)
    B = rng.standard_normal((9, 9))
    Kd = B @ B.T + 9 * np.eye(9)
    F = rng.standard_normal(9)
    nodes, g = np.array([7, 2, 2, 4]), np.array([1.0, -2.0, -2.0, 0.5])
    s = apply_dirichlet(sp.csr_matrix(Kd), F, nodes, g)
    fixed, free = np.array([2, 4, 7]), np.array([0, 1, 3, 5, 6, 8])
    gv = np.array([-2.0, 0.5, 1.0])
    assert np.array_equal(s.fixed, fixed) and np.array_equal(s.free, free)
    assert np.allclose(s.A.toarray(), Kd[np.ix_(free, free)], rtol=0, atol=0)
    assert np.allclose(s.b, F[free] - Kd[np.ix_(free, fixed)] @ gv, rtol=1e-14)
    u = s.expand(np.linalg.solve(Kd[np.ix_(free, free)], s.b))
    assert np.allclose((Kd @ u - F)[free], 0, atol=1e-12)  # free equations hold
    assert np.array_equal(u[fixed], gv)
    np.linalg.cholesky(s.A.toarray())  # SPD


def test_dirichlet_values_forms(square8):
    nodes = np.array([0, 3, 8])
    x, y = square8.points[nodes].T
    assert np.array_equal(dirichlet_values(square8, nodes, 2.0), [2.0, 2.0, 2.0])
    assert np.allclose(dirichlet_values(square8, nodes, lambda x, y: x + 10 * y), x + 10 * y)
    with pytest.raises(InputError):
        dirichlet_values(square8, nodes, [1.0, 2.0])
    with pytest.raises(InputError):
        apply_dirichlet(sp.eye(3, format="csr"), np.zeros(3), [5], [0.0])


def test_neumann_total_flux_and_missing_tag(square8):
    # integral of h = 1 + y over the right side (x = 1, y in [0, 1]) = 1.5
    F = assemble_neumann(square8, "right", lambda x, y: 1 + y)
    assert F.sum() == pytest.approx(1.5, rel=1e-14)
    assert F[square8.points[:, 0] < 1].max() == 0
    assert assemble_neumann(square8, ["left", "top"], 2.0).sum() == pytest.approx(4.0, rel=1e-14)
    with pytest.raises(MeshError, match="nowhere"):
        assemble_neumann(square8, "nowhere", 1.0)


def test_norms_of_interpolant_of_quadratic(make_square):
    """u = x^2 against its interpolant x on two triangles: the integrals are known exactly."""
    mesh = make_square(1)  # two triangles
    u = mesh.points[:, 0] ** 2  # corner values 0, 1, 1, 0: the interpolant is u_h = x
    e = error_norms(mesh, u, lambda x, y: x**2, lambda x, y: (2 * x, 0 * y))
    # ||x^2 - x||_L2^2 over the square = 1/30, ||2x - 1||^2 = 1/3
    assert e["L2"] == pytest.approx(math.sqrt(1 / 30), rel=1e-12)
    assert e["H1_semi"] == pytest.approx(math.sqrt(1 / 3), rel=1e-12)
    assert e["max_nodal"] == 0
    assert error_norms(mesh, u, lambda x, y: x**2)["H1_semi"] is None
    with pytest.raises(InputError):
        error_norms(mesh, u[:-1], lambda x, y: x)


def test_import_is_lean():
    code = ("import sys, femkit.fem; bad = [m for m in ('numba', 'skfem', 'pyamg', 'gmsh', 'matplotlib')"
            " if m in sys.modules]; print(bad)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
