"""Against felupe (an independent hyperelastic FEM package, test extra): a stable neo-Hookean
unit cube stretched to 1.5x, rollers on the three symmetry faces, the pulled face clamped
transversally; felupe given the same energy through its own (F-based, closed-form) stress and
elasticity tensor, on the same tetrahedra. Displacements agree to 1e-6 (measured 4e-14)."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.mesh.structured import structured_box
from femkit.solids import Dirichlet, ElasticBody, material, solve_static

fem = pytest.importorskip("felupe", reason="felupe (test extra) is not installed: pip install -e '.[test]'")


def _felupe_snh(mu, lam2):
    """``W = mu/2 (I_C - 3) - mu (J - 1) + lam2/2 (J - 1)^2`` written with ``F`` and its cofactor,
    not with the stretches: ``P = mu F + (lam2 (J - 1) - mu) cof F``."""
    from felupe.math import cdya_ik, cdya_il, det, dya, identity, inv, transpose

    def stress(x, mu, lam2):
        F, statevars = x[0], x[-1]
        J = det(F)
        return [mu * F + (lam2 * (J - 1) - mu) * J * transpose(inv(F, J)), statevars]

    def elasticity(x, mu, lam2):
        F = x[0]
        J = det(F)
        iFT = transpose(inv(F, J))
        a = lam2 * (J - 1) - mu
        eye = identity(F)
        return [mu * cdya_ik(eye, eye) + lam2 * J**2 * dya(iFT, iFT)
                + a * J * (dya(iFT, iFT) - cdya_il(iFT, iFT))]

    return fem.Material(stress, elasticity, mu=mu, lam2=lam2)


def test_stretched_block_matches_felupe():
    mat = material("stable_neo_hookean", E=1.0, nu=0.3)
    box = structured_box(3, 3, 3)
    mesh = fem.Mesh(box.points, box.cells, "tetra")
    field = fem.FieldContainer([fem.Field(fem.RegionTetra(mesh), dim=3)])
    boundaries, _ = fem.dof.uniaxial(field, move=0.5, clamped=True, return_loadcase=True)
    solid = fem.SolidBody(_felupe_snh(mat.mu, mat.lam + mat.mu), field)
    ramp = {boundaries["move"]: fem.math.linsteps([0, 0.5], num=5)}
    fem.Job(steps=[fem.Step(items=[solid], ramp=ramp, boundaries=boundaries)]).evaluate(tol=1e-12, verbose=0)
    u_felupe = field[0].values

    X = box.points
    body = ElasticBody.from_mesh(box, mat)
    bc = Dirichlet(body.n, 3)
    for axis in range(3):
        bc.fix(np.flatnonzero(np.isclose(X[:, axis], 0.0)), components=[axis])
    right = np.flatnonzero(np.isclose(X[:, 0], 1.0))
    bc.fix(right, components=[0], displacement=0.5).fix(right, components=[1, 2])
    res = solve_static(body, bc, load_steps=5)
    assert res.converged
    assert np.abs(res.u - u_felupe).max() <= 1e-6 * 0.5
    assert np.ptp(res.u[:, 1]) > 0.05          # a real lateral contraction, not a trivial state
