"""Mass matrices (femkit.fem.mass) against scikit-fem's ``mass`` bilinear form, P1 and P2,
triangles and tetrahedra, and the positivity of the lumped ones."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.case.poisson import reference
from femkit.fem.mass import mass_matrix
from femkit.mesh import generate, refine

from ._tets import perturbed_box


def _tri():
    m = refine(generate("unit_square", 0.5), 2)
    rng = np.random.default_rng(1)
    p = m.points.copy()
    inner = ((p > 1e-9) & (p < 1 - 1e-9)).all(axis=1)
    p[inner] += 0.04 * rng.uniform(-1, 1, (int(inner.sum()), 2))
    from femkit.mesh import Mesh

    return Mesh(p, m.cells)


MESHES = {"triangles": _tri, "tetrahedra": lambda: perturbed_box(3)}


@pytest.mark.parametrize("element", ["P1", "P2"])
@pytest.mark.parametrize("shape", sorted(MESHES))
def test_consistent_mass_equals_scikit_fem(shape, element):
    mesh = MESHES[shape]()
    rho = 1.0 + np.random.default_rng(2).random(mesh.n_cells)
    M = mass_matrix(mesh, element=element, density=rho)
    ref = reference.mass(mesh, rho, element)
    assert M.shape == ref.shape
    assert abs(M - ref).max() <= 1e-12 * abs(ref).max()
    unit = mass_matrix(mesh, element=element)
    assert abs(unit - reference.mass(mesh, None, element)).max() <= 1e-12 * abs(unit).max()
    # u = 1: the total measure; u = x: the first moment (P1 and P2 reproduce linear functions)
    ones = np.ones(M.shape[0])
    assert unit @ ones @ ones == pytest.approx(mesh.volumes().sum(), rel=1e-13)


@pytest.mark.parametrize("element", ["P1", "P2"])
@pytest.mark.parametrize("shape", sorted(MESHES))
def test_lumped_mass_is_positive_and_keeps_the_total(shape, element):
    mesh = MESHES[shape]()
    rho = 1.0 + np.random.default_rng(3).random(mesh.n_cells)
    L = mass_matrix(mesh, element=element, lumped=True, density=rho)
    M = mass_matrix(mesh, element=element, density=rho)
    d = L.diagonal()
    assert L.nnz == len(d) and d.min() > 0
    assert d.sum() == pytest.approx(M.sum(), rel=1e-13)
    assert d.sum() == pytest.approx((rho * mesh.volumes()).sum(), rel=1e-13)
    if element == "P1":  # P1: the row sums
        np.testing.assert_allclose(d, np.asarray(M.sum(axis=1)).ravel(), rtol=1e-13)
    else:  # P2: row sums would not be positive (zero or negative vertex masses)
        assert np.asarray(M.sum(axis=1)).ravel()[:mesh.n_points].min() <= 1e-15 * d.max()
