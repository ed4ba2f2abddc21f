"""Material records: parameters, conversions, bad input, the registry."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import DegenerateMeshError, MaterialError, UnknownNameError
from femkit.solids import MATERIALS, ElasticBody, lame_from_young, material, rest_shape

NAMES = ["linear", "corotational", "stvk", "stable_neo_hookean"]


@pytest.mark.parametrize("E,nu", [(1.0, 0.0), (210e9, 0.3), (5.0, 0.49), (3.0, -0.5)])
def test_young_poisson_round_trip(E, nu):
    mu, lam = lame_from_young(E, nu)
    # textbook relations: E = mu (3 lam + 2 mu) / (lam + mu), nu = lam / (2 (lam + mu))
    mat = MATERIALS.get("stvk")(mu, lam)
    assert mat.young == pytest.approx(E, rel=1e-12)
    assert mat.poisson == pytest.approx(nu, rel=1e-12, abs=1e-15)
    assert mu == pytest.approx(E / (2 * (1 + nu)))


@pytest.mark.parametrize("kwargs,match", [
    (dict(E=0.0, nu=0.3), "Young's modulus"),
    (dict(E=-1.0, nu=0.3), "Young's modulus"),
    (dict(E=1.0, nu=0.5), "Poisson ratio"),
    (dict(E=1.0, nu=0.7), "Poisson ratio"),
    (dict(E=1.0, nu=-1.0), "Poisson ratio"),
    (dict(E=1.0, nu=0.3, density=0.0), "density"),
    (dict(E=1.0, nu=0.3, density=-2.0), "density"),
    (dict(mu=-1.0, lam=1.0), "mu"),
    (dict(mu=1.0, lam=-1.0), "bulk modulus"),
    (dict(mu=float("nan"), lam=1.0), "finite"),
    (dict(E=1.0, mu=1.0), "either"),
], ids=lambda v: str(v) if not isinstance(v, dict) else "-".join(f"{k}={x}" for k, x in v.items()))
@pytest.mark.parametrize("name", NAMES)
def test_bad_parameters_raise_material_error(name, kwargs, match):
    with pytest.raises(MaterialError, match=match):
        material(name, **kwargs)


def test_unknown_material_lists_the_valid_ones():
    with pytest.raises(UnknownNameError, match="stable_neo_hookean"):
        material("neo", E=1.0, nu=0.3)


@pytest.mark.parametrize("name", NAMES)
def test_stretch_derivatives_at_rest(name):
    mat = material(name, mu=1.3, lam=2.1)
    if name == "linear":
        return
    W, g, H = mat.stretch_derivatives(np.ones(3))
    assert W == 0.0 and np.all(g == 0.0)
    # the diagonal block of linear elasticity: 2 mu I + lam 1 1^T
    np.testing.assert_allclose(H, 2 * 1.3 * np.eye(3) + 2.1, rtol=1e-14)


def test_inverted_and_flat_rest_elements_are_named():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    with pytest.raises(DegenerateMeshError, match="inverted") as info:
        rest_shape(X, [[0, 1, 2, 3], [0, 2, 1, 3]])
    assert info.value.element_ids == [1]
    with pytest.raises(DegenerateMeshError, match="zero-volume"):
        rest_shape(np.array([[0.0, 0], [1, 0], [2, 0]]), [[0, 1, 2]])
    with pytest.raises(DegenerateMeshError):
        ElasticBody(X, [[0, 1, 2, 3], [0, 2, 1, 3]], material("stvk", mu=1, lam=1))
