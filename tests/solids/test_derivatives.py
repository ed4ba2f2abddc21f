"""Stress, tangent, forces and Hessians of every material against central finite differences
of the energy (Kim & Eberle's protocol: step swept 1e-4 .. 1e-8, the smallest relative
difference <= 1e-6), on random, inverted (one and three reflections) and repeated-stretch
deformations; the projected tangent against a numerically eigen-clamped one."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from femkit.solids import MATERIALS, ElasticBody, invertible_svd, point_tangent

sys.path.insert(0, str(Path(__file__).parent))  # importlib mode: reach the shared helpers
from _meshes import assembled_fd_errors, mesh_by_dim, min_rel, random_rotation  # noqa: E402

NAMES = ["linear", "corotational", "stvk", "stable_neo_hookean"]
FLIP_SYMMETRIC = ["linear", "stvk", "stable_neo_hookean"]  # energy unchanged by s_i, s_j -> -s_i, -s_j


def _mat(name):
    return MATERIALS.get(name)(1.3, 2.1)


def _F(kind: str, d: int, rng) -> np.ndarray:
    U, V = random_rotation(rng, d), random_rotation(rng, d)
    s = rng.uniform(0.6, 1.5, d)
    if kind == "random":
        return np.eye(d) + 0.3 * rng.standard_normal((d, d))
    if kind == "one_reflection":
        s[-1] = -s[-1]
    elif kind == "three_reflections":
        s = -s
    elif kind == "repeated_two":
        s[1] = s[0]
    elif kind == "repeated_all":
        s[:] = s[0]
    elif kind == "nearly_repeated":
        s[1] = s[0] * (1.0 + 1e-10)
    elif kind == "opposite_pair":          # s_i = -s_j: the twist quotient's 0/0
        s[1] = s[0]
        s[0] = -s[0]
    return U @ np.diag(s) @ V.T


CASES = {2: ["random", "one_reflection", "repeated_two", "nearly_repeated", "opposite_pair"],
         3: ["random", "one_reflection", "three_reflections", "repeated_two", "repeated_all",
             "nearly_repeated", "opposite_pair"]}
POINT_CASES = [pytest.param(name, d, kind, id=f"{name}-{d}d-{kind}")
               for name in NAMES for d in (2, 3) for kind in CASES[d]
               # co-rotational on signed stretches has a kink where s_i = -s_j (not smooth there)
               if not (kind == "opposite_pair" and name not in FLIP_SYMMETRIC)]


def test_invertible_svd_signs(rng):
    for kind, negatives in (("one_reflection", 1), ("three_reflections", 1), ("random", None)):
        F = _F(kind, 3, rng)
        U, s, V = invertible_svd(F)
        assert np.linalg.det(U) == pytest.approx(1.0) and np.linalg.det(V) == pytest.approx(1.0)
        np.testing.assert_allclose(U @ np.diag(s) @ V.T, F, atol=1e-13)
        if negatives:
            assert (s < 0).sum() == negatives and s[-1] < 0


def assert_point_derivatives(mat, F):
    """``P`` against finite differences of ``psi`` and ``dP/dF`` against those of ``P``."""
    d = F.shape[0]
    psi, P, A = point_tangent(mat, F)

    def dpsi(h):
        out = np.zeros((d, d))
        for a in range(d):
            for b in range(d):
                E = np.zeros((d, d))
                E[a, b] = h
                out[a, b] = (point_tangent(mat, F + E)[0] - point_tangent(mat, F - E)[0]) / (2 * h)
        return out

    def dP(h):
        cols = []
        for c in range(d * d):
            E = np.zeros(d * d)
            E[c] = h
            E = E.reshape(d, d)
            cols.append(((point_tangent(mat, F + E)[1] - point_tangent(mat, F - E)[1]) / (2 * h)).ravel())
        return np.column_stack(cols)

    assert np.isfinite(psi)
    assert min_rel(P, dpsi) <= 1e-6
    assert min_rel(A, dP) <= 1e-6


@pytest.mark.parametrize("name,d,kind", POINT_CASES)
def test_stress_and_tangent_match_finite_differences(name, d, kind, rng):
    assert_point_derivatives(_mat(name), _F(kind, d, rng))


@pytest.mark.parametrize("name,d,kind", POINT_CASES)
def test_projected_tangent_equals_numerically_clamped(name, d, kind, rng):
    mat = _mat(name)
    F = _F(kind, d, rng)
    A = point_tangent(mat, F)[2]
    w, Q = np.linalg.eigh(0.5 * (A + A.T))
    clamped = (Q * np.maximum(w, 0.0)) @ Q.T
    Ap = point_tangent(mat, F, project=True)[2]
    np.testing.assert_allclose(Ap, clamped, atol=1e-10 * np.abs(A).max())
    assert np.linalg.eigvalsh(Ap).min() >= -1e-12 * np.abs(A).max()


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("d", [2, 3], ids=["triangles", "tetrahedra"])
def test_assembled_gradient_and_hessian_match_finite_differences(name, d, rng):
    X, cells = mesh_by_dim(d)
    body = ElasticBody(X, cells, _mat(name))
    x = X + 0.15 * rng.standard_normal(X.shape)
    inverted = (np.linalg.det(body.deformation_gradients(x)) < 0).sum()
    grad_err, hess_err = assembled_fd_errors(body, x)
    assert grad_err <= 1e-6 and hess_err <= 1e-6
    H = body.hessian(x)
    np.testing.assert_allclose(H.toarray(), H.toarray().T, atol=1e-12 * abs(H).max())
    assert inverted >= 0  # recorded: random positions of this size invert some elements


@pytest.mark.parametrize("name", NAMES)
def test_projected_mesh_hessian_is_psd_and_bounds_hold(name, rng):
    X, cells = mesh_by_dim(3)
    body = ElasticBody(X, cells, _mat(name))
    x = X + 0.3 * rng.standard_normal(X.shape)
    Hp = body.hessian(x, project=True).toarray()
    H = body.hessian(x).toarray()
    scale = np.abs(H).max()
    assert np.linalg.eigvalsh(Hp).min() >= -1e-10 * scale
    # the per-node bound of the negative part: H + diag(e) is PSD
    e = np.repeat(body.negative_bound(x), 3)
    assert np.linalg.eigvalsh(H + np.diag(e)).min() >= -1e-10 * scale


@pytest.mark.parametrize("name", NAMES)
def test_element_stresses_are_the_point_stresses(name, rng):
    X, cells = mesh_by_dim(3)
    mat = _mat(name)
    body = ElasticBody(X, cells, mat)
    x = X + 0.2 * rng.standard_normal(X.shape)
    P = body.stresses(x)
    F = body.deformation_gradients(x)
    for e in range(len(cells)):
        np.testing.assert_allclose(P[e], point_tangent(mat, F[e])[1], atol=1e-12 * np.abs(P).max())
