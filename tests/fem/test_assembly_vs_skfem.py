"""Stiffness and one-point load against scikit-fem on the same mesh (1e-12 relative).

scikit-fem 12's ``intorder=1`` on triangles is its 3-point rule, not the centroid, so the
one-point comparisons hand scikit-fem the centroid rule explicitly (``CENTROID``).
"""

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementTriP1, LinearForm, asm
from skfem.helpers import dot, grad
from skfem.models.poisson import laplace, unit_load

from femkit.fem import SparsityPattern, assemble_load, assemble_stiffness


CENTROID = (np.array([[1 / 3], [1 / 3]]), np.array([0.5]))


def rel(a, b):
    a = sp.csr_matrix(a) if sp.issparse(a) else np.asarray(a)
    d = a - b
    num = sp.linalg.norm(d) if sp.issparse(d) else np.linalg.norm(d)
    den = sp.linalg.norm(b) if sp.issparse(b) else np.linalg.norm(b)
    return num / den


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_stiffness_constant_kappa(sk_mesh, backend):
    sk, mesh = sk_mesh
    K_ref = asm(laplace, Basis(sk, ElementTriP1()))
    K = assemble_stiffness(mesh, backend=backend)
    assert rel(K, K_ref) < 1e-12
    assert abs(K - K.T).max() < 1e-14


def _skfem_kappa_form(kappa_fn):
    @BilinearForm
    def form(u, v, w):
        return kappa_fn(w.x[0], w.x[1]) * dot(grad(u), grad(v))

    return form


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_stiffness_variable_kappa_at_barycentres(sk_mesh, backend):
    sk, mesh = sk_mesh
    kappa = lambda x, y: 1.0 + x**2 + np.sin(3 * y)  # noqa: E731
    K_ref = asm(_skfem_kappa_form(kappa), Basis(sk, ElementTriP1(), quadrature=CENTROID))
    assert rel(assemble_stiffness(mesh, kappa, backend=backend), K_ref) < 1e-12


@pytest.mark.parametrize("table", [{1: 2.0, 2: 1e6}, {"west": 2.0, "east": 1e6}], ids=["tag-ids", "tag-names"])
def test_stiffness_per_region_kappa(sk_mesh, table):
    sk, mesh0 = sk_mesh
    from femkit.mesh import Mesh

    tags = np.where(mesh0.centroids()[:, 0] < 0.5, 1, 2)
    mesh = Mesh(mesh0.points, mesh0.triangles, cell_tags=tags, tag_names={"west": 1, "east": 2})
    kappa_of = lambda x, y: np.where(x < 0.5, 2.0, 1e6)  # noqa: E731  (same split, at centroids)
    K_ref = asm(_skfem_kappa_form(kappa_of), Basis(sk, ElementTriP1(), quadrature=CENTROID))
    assert rel(assemble_stiffness(mesh, table), K_ref) < 1e-12
    assert rel(assemble_stiffness(mesh, np.where(tags == 1, 2.0, 1e6)), K_ref) < 1e-12


@pytest.mark.parametrize("f", [1.0, lambda x, y: np.exp(x) * np.cos(2 * y)], ids=["unit", "exp-cos"])
def test_one_point_load(sk_mesh, f):
    sk, mesh = sk_mesh
    basis = Basis(sk, ElementTriP1(), quadrature=CENTROID)
    if callable(f):
        form = LinearForm(lambda v, w: f(w.x[0], w.x[1]) * v)
    else:
        form = unit_load
    F_ref = asm(form, basis)
    assert rel(assemble_load(mesh, f), F_ref) < 1e-12


@pytest.mark.parametrize("rule,intorder", [("gauss3", 2), ("gauss6", 4), ("gauss7", 5)])
def test_higher_order_load_matches_skfem_exact_rule(sk_mesh, rule, intorder):
    """For a polynomial source the rule is exact, so it agrees with skfem's rule of that order."""
    sk, mesh = sk_mesh
    deg = intorder - 1  # f * N_j has degree deg + 1 = intorder
    f = lambda x, y: (1 + x + 2 * y) ** deg  # noqa: E731
    F_ref = asm(LinearForm(lambda v, w: f(w.x[0], w.x[1]) * v), Basis(sk, ElementTriP1(), intorder=intorder))
    assert rel(assemble_load(mesh, f, rule=rule), F_ref) < 1e-12


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_pattern_backends_agree_and_reuse(sk_mesh, backend):
    sk, mesh = sk_mesh
    pat = SparsityPattern.from_mesh(mesh, backend=backend)
    ref = SparsityPattern.from_mesh(mesh, backend="numpy")
    assert np.array_equal(pat.indptr, ref.indptr) and np.array_equal(pat.indices, ref.indices)
    assert np.array_equal(pat.slots, ref.slots)
    K_ref = asm(laplace, Basis(sk, ElementTriP1()))
    for scale in (1.0, 3.5):  # reuse the pattern with a new coefficient
        assert rel(assemble_stiffness(mesh, scale, pattern=pat), scale * K_ref) < 1e-12
    assert pat.nnz == K_ref.nnz
