"""Materials designed by their energy of the principal stretches (Xu et al. 2015): a built-in's
expression given as a user's energy equals the built-in to 1e-12 (the built-ins against
hand-written formulas: test_builtin_energies.py); user
energies' stresses, tangents, assembled gradients and Hessians against central finite
differences (step swept 1e-4 .. 1e-8, smallest relative difference <= 1e-6), inverted and
repeated stretches included; the checks at construction, each with its one-line error."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.errors import MaterialError
from femkit.solids import ElasticBody
from femkit.solids.materials import (MATERIALS, EnergyMaterial, designed, material,
                                     material_from_spec)

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helpers
from _meshes import assembled_fd_errors, mesh_by_dim  # noqa: E402
from test_derivatives import _F, assert_point_derivatives  # noqa: E402

BUILTIN = ["corotational", "stvk", "stable_neo_hookean"]

#: user energies: (energy, constants); each stress-free and stable at rest
USER = {
    "separable_fgh": ({"f": "mu*(s-1)**2", "g": "k*(s-1)**2", "h": "lam/2*(J-1)**2"},
                      {"mu": 1.3, "k": 0.4, "lam": 2.1}),
    # stiffer in tension only: a cubic added for s > 1 (C2 at s = 1)
    "tension_stiffening": ({"f": "mu*(s-1)**2 + where(s > 1, k*(s-1)**3, 0)",
                            "h": "lam/2*(J-1)**2"}, {"mu": 1.0, "k": 5.0, "lam": 3.0}),
    # a spline-like response: different quadratics/cubics each side of s = 1
    "spline_like": ({"f": "where(s < 1, a*(s-1)**2, a*(s-1)**2 + b*(s-1)**3 + c*(s-1)**4)",
                     "h": "lam/2*(J-1)**2"}, {"a": 0.8, "b": -0.3, "c": 2.0, "lam": 1.5}),
    "full_W": ("mu*((s1-1)**2 + (s2-1)**2 + (s3-1)**2) + lam/2*(J-1)**2"
               " + k*(s1*s2 + s2*s3 + s1*s3 - 3)**2", {"mu": 1.1, "lam": 0.7, "k": 0.2}),
}


def _user(name):
    energy, constants = USER[name]
    return EnergyMaterial.from_energy(energy, constants)


@pytest.mark.parametrize("name", BUILTIN)
def test_designed_twins_stretch_energy_equals_the_builtins(name, rng):
    """A built-in's energy expression given as a user's energy (its own generated module, one
    energy, not the built-ins' shared one): its energy of the stretches and their first and
    second derivatives equal the built-in's to rounding, in 2D and 3D, at random, inverted
    (negative) and repeated stretches. Around that function both modules hold the same generated
    point and element code, compared on a body by the next test."""
    hand = MATERIALS.get(name)(1.3, 2.1, 1.0)
    gen = designed(hand)
    assert gen.kernels() is not hand.kernels()
    for d in (2, 3):
        for k in range(12):
            s = rng.uniform(0.5, 1.6, d)
            if k % 3 == 1:
                s[-1] = -s[-1]                      # an inverted element's signed stretches
            elif k % 3 == 2:
                s[1] = s[0]                         # repeated stretches
            for a, b in zip(hand.stretch_derivatives(s), gen.stretch_derivatives(s)):
                np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * max(np.abs(a).max(), 1.0))


@pytest.mark.xdist_group("designed_stable_neo_hookean")   # one compile of the module
@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_designed_twin_equals_the_builtin_on_a_body(d, rng):
    """The stable neo-Hookean energy given as a user's energy evaluates a body (energy,
    gradient, Hessian) the same as the built-in to rounding, elements inverted included. One
    built-in: every designed module compiles its point and element passes anew (~30 s), and
    the other built-ins' twins differ from this one only in the stretch function compared above
    (this module is also the one tests/solids/test_energy_case.py designs)."""
    hand = MATERIALS.get("stable_neo_hookean")(1.3, 2.1, 1.0)
    gen = designed(hand)
    assert gen.kernels() is not hand.kernels()
    X, cells = mesh_by_dim(d)
    for scale in (0.05, 0.4):                       # the larger one inverts elements
        x = X + scale * rng.standard_normal(X.shape)
        a, b = ElasticBody(X, cells, hand), ElasticBody(X, cells, gen)
        for level_a, level_b in zip(a.evaluate(x, project=False), b.evaluate(x, project=False)):
            ra = level_a.toarray() if hasattr(level_a, "toarray") else np.asarray(level_a)
            rb = level_b.toarray() if hasattr(level_b, "toarray") else np.asarray(level_b)
            np.testing.assert_allclose(rb, ra, rtol=0, atol=1e-12 * max(np.abs(ra).max(), 1.0))


@pytest.mark.parametrize("name", BUILTIN)
def test_rest_moduli_of_the_expression_are_the_materials(name):
    hand = material(name, E=2.6, nu=0.3)
    gen = designed(hand)
    assert gen.mu == pytest.approx(hand.mu, rel=1e-12)
    assert gen.lam == pytest.approx(hand.lam, rel=1e-12)


def _module(name: str):
    """The mark that runs every test of the user energy ``name`` on one worker: its module is
    compiled once (~30 s on a cold cache), not by each worker that meets it first."""
    return pytest.mark.xdist_group(f"designed_{name}")


POINT = [pytest.param(name, d, kind, id=f"{name}-{d}d-{kind}", marks=_module(name))
         for name in USER for d in (2, 3)
         for kind in ("random", "one_reflection", "repeated_two", "nearly_repeated")]


@pytest.mark.parametrize("name,d,kind", POINT)
def test_user_stress_and_tangent_match_finite_differences(name, d, kind, rng):
    assert_point_derivatives(_user(name), _F(kind, d, rng))


@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
@pytest.mark.parametrize("name", [pytest.param(n, marks=_module(n)) for n in ("separable_fgh", "full_W")])
def test_user_assembled_gradient_and_hessian_match_finite_differences(name, d, rng):
    """A designed module's element pass (the same generated code around every energy) assembles
    the gradient and Hessian of its energy: one energy of each form (``f, g, h`` and ``W``); the
    point functions of every user energy are checked above, the element pass of the built-ins
    in test_derivatives.py (each designed module compiles its element pass anew, ~10 s)."""
    X, cells = mesh_by_dim(d)
    body = ElasticBody(X, cells, _user(name))
    x = X + 0.15 * rng.standard_normal(X.shape)
    grad_err, hess_err = assembled_fd_errors(body, x)
    assert grad_err <= 1e-6 and hess_err <= 1e-6


def test_separable_form_moduli_follow_xu_et_al():
    """``W = sum f(s_i) + h(J)`` with ``f = mu (s-1)^2``, ``h = lam/2 (J-1)^2``: at rest the
    stretch Hessian is ``2 mu I + lam 1 1^T``, i.e. Lame moduli ``(mu, lam)``; ``g = k (s-1)^2``
    adds ``k`` to the off-diagonal (``lam + k``) and ``k`` to the diagonal (``mu + ... ``)."""
    m = _user("separable_fgh")
    mu, k, lam = 1.3, 0.4, 2.1
    # g(s_i s_j): d2/ds_i^2 = 2k (two pairs) -> diagonal 2 mu + lam + 4k, off-diagonal lam + 2k
    assert m.lam == pytest.approx(lam + 2 * k, rel=1e-13)
    assert m.mu == pytest.approx(0.5 * ((2 * mu + lam + 4 * k) - (lam + 2 * k)), rel=1e-13)


BAD = {
    "not_stress_free": (({"f": "mu*(s-1)**2 + mu*s"}, {"mu": 1.0}), "not stress-free"),
    "unstable": (({"f": "-mu*(s-1)**2"}, {"mu": 1.0}), "unstable at rest"),
    "negative_bulk": (({"f": "mu*(s-1)**2", "h": "lam/2*(J-1)**2"}, {"mu": 1.0, "lam": -1.0}),
                      "bulk modulus"),
    "not_symmetric": (("mu*(s1-1)**2 + 2*mu*(s2-1)**2 + mu*(s3-1)**2", {"mu": 1.0}),
                      "not symmetric"),
    "not_finite": (({"f": "log(s-1)**2"}, {}), "not finite"),
    "unsafe_call": (({"f": "__import__('os').system('true')"}, {}), "is not allowed"),
    "attribute": (({"f": "s.real"}, {}), "attribute access"),
    "unknown_name": (({"f": "nu*(s-1)**2"}, {"mu": 1.0}), "unknown name 'nu'"),
    "missing_constant": (({"f": "mu*(s-1)**2"}, {"mu": "soft"}), "must be a number"),
    "bare_comparison": (({"f": "(s > 1)*(s-1)**2"}, {}), "comparison"),
    "both_forms": (({"W": "s1", "f": "s"}, {}), "not both"),
    "reserved_constant": (({"f": "J*(s-1)**2"}, {"J": 1.0}), "reserved"),
    "syntax": (({"f": "mu*(s-1"}, {"mu": 1.0}), "syntax error"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_energies_are_one_line_material_errors(case):
    (energy, constants), words = BAD[case]
    with pytest.raises(MaterialError, match=words) as info:
        EnergyMaterial.from_energy(energy, constants)
    assert "\n" not in str(info.value)


def test_material_from_spec_both_forms():
    m = material_from_spec({"energy": {"f": "mu*(s-1)**2", "g": "0", "h": "lam/2*(J-1)**2"},
                            "constants": {"mu": 3.4e5, "lam": 1.4e6}, "density": 1000})
    assert isinstance(m, EnergyMaterial) and m.density == 1000.0
    assert m.mu == pytest.approx(3.4e5, rel=1e-12) and m.lam == pytest.approx(1.4e6, rel=1e-12)
    assert material_from_spec({"model": "stvk", "mu": 1.0, "lam": 2.0}).name == "stvk"
    with pytest.raises(MaterialError, match="valid keys"):
        material_from_spec({"energy": "s1", "stiffness": 1})
    with pytest.raises(Exception, match="valid materials"):
        material_from_spec({"model": "rubber", "E": 1.0, "nu": 0.3})


@pytest.mark.parametrize("name", ["stable_neo_hookean", "stvk", "separable_fgh", "full_W"])
def test_uniaxial_curve_starts_with_young_modulus_and_poisson_ratio(name):
    from femkit.solids.materials.curves import uniaxial_curve

    mat = material(name, E=2.6, nu=0.3) if name in MATERIALS else _user(name)
    eps = 1e-5
    t, P = uniaxial_curve(mat, [1.0 - eps, 1.0, 1.0 + eps])
    assert P[1] == pytest.approx(0.0, abs=1e-12)
    assert (P[2] - P[0]) / (2 * eps) == pytest.approx(mat.young, rel=1e-8)
    assert (t[2] - t[0]) / (2 * eps) == pytest.approx(-mat.poisson, rel=1e-7)
