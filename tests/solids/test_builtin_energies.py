"""The built-in materials are energy expressions with generated kernels (one mechanism with the
materials a user designs): their energies, stretch derivatives, assembled gradients and
(projected) Hessians equal hand-written formulas derived independently (tests/solids/_reference.py:
plain NumPy, LAPACK's SVD) -- to 1e-12 at the stretch level, 1e-10 on a mesh -- on random,
inverted (one and three reflections), nearly collapsed and repeated stretches."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.solids import MATERIALS, ElasticBody

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helpers
from _meshes import mesh_by_dim  # noqa: E402
from _reference import NAMES, assembled, hand  # noqa: E402

MU, LAM = 1.3, 2.1


def _stretches(rng, d: int, kind: str) -> np.ndarray:
    s = rng.uniform(0.3, 2.5, (50, d))
    if kind == "one_reflection":
        s[:, -1] *= -1.0
    elif kind == "three_reflections":
        s = -s
    elif kind == "repeated":
        s[:, 1] = s[:, 0]
    elif kind == "collapsed":
        s[:, -1] = rng.uniform(-1e-6, 1e-6, 50)
    return s


KINDS = {2: ["random", "one_reflection", "repeated", "collapsed"],
         3: ["random", "one_reflection", "three_reflections", "repeated", "collapsed"]}
STRETCH_CASES = [pytest.param(name, d, kind, id=f"{name}-{d}d-{kind}")
                 for name in NAMES for d in (2, 3) for kind in KINDS[d]]


@pytest.mark.parametrize("name,d,kind", STRETCH_CASES)
def test_generated_stretch_derivatives_equal_the_hand_written(name, d, kind, rng):
    mat = MATERIALS.get(name)(MU, LAM)
    s = _stretches(rng, d, kind)
    W_ref, g_ref, H_ref = hand(name, s, MU, LAM)
    for k in range(len(s)):
        W, g, H = mat.stretch_derivatives(s[k])
        scale = max(abs(W_ref[k]), np.abs(g_ref[k]).max(), np.abs(H_ref[k]).max(), 1.0)
        assert abs(W - W_ref[k]) <= 1e-12 * scale
        np.testing.assert_allclose(g, g_ref[k], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(H, H_ref[k], rtol=0, atol=1e-12 * scale)


def test_builtins_share_one_generated_module():
    mods = {MATERIALS.get(n)(MU, LAM).kernels() for n in MATERIALS.names()}
    assert len(mods) == 1
    mod = mods.pop()
    assert mod.__name__.startswith("femkit_energy_")
    from femkit.elements import compiled

    for name in ("corotational_energy", "stvk_energy", "stable_neo_hookean_energy", "stretch_energy"):
        assert not hasattr(compiled, name)          # no hand-written energy left in the library


@pytest.mark.parametrize("project", [False, True], ids=["exact", "projected"])
@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
@pytest.mark.parametrize("name", NAMES)
def test_assembled_equals_numpy_svd_derivative_of_the_hand_formula(name, d, project, rng):
    X, cells = mesh_by_dim(d)
    body = ElasticBody(X, cells, MATERIALS.get(name)(MU, LAM))
    for scale in (0.05, 0.4):                       # the larger one inverts elements
        x = X + scale * rng.standard_normal(X.shape)
        E_ref, g_ref, H_ref = assembled(name, X, cells, x, MU, LAM, project)
        E, g, H, _ = body.evaluate(x, project=project)
        assert E.sum() == pytest.approx(E_ref, rel=1e-12)
        np.testing.assert_allclose(g.ravel(), g_ref, rtol=0, atol=1e-12 * np.abs(g_ref).max())
        np.testing.assert_allclose(H.toarray(), H_ref, rtol=0, atol=1e-10 * np.abs(H_ref).max())
