"""``femkit check`` integrates the load with the case's own rule on both sides.

femkit solves with the case's ``quadrature.load`` rule; scikit-fem gets the same points and
weights (:func:`femkit.case.poisson.reference.skfem_quadrature`). The mapping is checked against
scikit-fem's own exact rules (``intorder``) on polynomial sources, an expected value femkit does
not compute; the check is shown to fail when the two sides' rules differ.
"""

from pathlib import Path

import numpy as np
import pytest

import femkit
from femkit.case.poisson import cross_check as cc
from femkit.case.poisson import reference
from femkit.cli import main
from femkit.fem import QUADRATURE, TET_QUADRATURE, assemble_load, get_rule
from femkit.mesh import generate

CASES = Path(__file__).resolve().parents[2] / "cases"


def _rel(a, b) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def meshes():
    return {2: generate("unit_square", h=0.25), 3: generate("kuhn_cube", h=0.5)}


def _poly(dim: int, degree: int):
    """A source of total degree ``degree`` without the symmetries of the rules' orbits."""
    if dim == 2:
        return lambda x, y: (1 + 2 * x + 5 * y) ** degree + x ** degree
    return lambda x, y, z: (1 + 2 * x + 5 * y + 3 * z) ** degree + x ** degree * (degree > 0)


@pytest.mark.parametrize("dim, name", [(2, n) for n in QUADRATURE] + [(3, n) for n in TET_QUADRATURE])
def test_scikit_fem_given_femkit_rule_is_exact_where_the_rule_is(meshes, dim, name):
    """f N_j of degree = the rule's degree: femkit's rule, handed to scikit-fem, gives scikit-fem's
    exact load (its own rule of order 9, exact for these integrands of degree <= 7; its
    ``intorder=5`` on tetrahedra is not exact at degree 5), and femkit's load agrees."""
    import skfem

    mesh = meshes[dim]
    rule = get_rule(name, dim=dim)
    f = _poly(dim, rule.degree - 1)
    _, F_rule = reference.assemble(mesh, np.ones(mesh.n_cells), f, rule=name)
    m = (skfem.MeshTri(mesh.points.T.copy(), mesh.cells.T.copy(), sort_t=False) if dim == 2
         else skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy(), sort_t=False))
    element = skfem.ElementTriP1() if dim == 2 else skfem.ElementTetP1()
    exact = skfem.LinearForm(lambda v, w: f(*w.x) * v).assemble(
        skfem.Basis(m, element, intorder=9))
    assert _rel(F_rule, exact) <= 1e-12
    assert _rel(assemble_load(mesh, f, rule=name), F_rule) <= 1e-12


@pytest.mark.parametrize("dim, name", [(2, n) for n in QUADRATURE] + [(3, n) for n in TET_QUADRATURE])
def test_scikit_fem_uses_the_same_points_as_femkit(meshes, dim, name):
    """On a source no rule integrates exactly, the two loads agree to round-off only when the
    points and weights are the same ones in the same cells (a relabelled but still exact rule,
    e.g. vertices taken in another order, differs here)."""
    mesh = meshes[dim]
    f = ((lambda x, y: np.exp(3 * x) * np.cos(5 * y + x * y)) if dim == 2
         else (lambda x, y, z: np.exp(3 * x) * np.cos(5 * y + x * z)))
    _, F_rule = reference.assemble(mesh, np.ones(mesh.n_cells), f, rule=name)
    assert _rel(F_rule, assemble_load(mesh, f, rule=name)) <= 1e-12


@pytest.mark.parametrize("path, overrides", [
    ("cube.yaml", {}),
    ("fichera.yaml", {}),
    ("poisson_unit_square.yaml", {"quadrature.load": "gauss3"}),
], ids=["cube gauss4", "fichera gauss4", "unit square gauss3"])
def test_check_passes_with_the_case_load_rule(capsys, path, overrides):
    argv = ["check", str(CASES / path)] + [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    code = main(argv)
    out = capsys.readouterr().out
    assert code == 0, out
    assert "FAIL" not in out
    rule = overrides.get("quadrature.load", "gauss4")
    assert f"quadrature '{rule}' on both sides" in out


def test_check_fails_when_scikit_fem_integrates_with_another_rule(monkeypatch):
    """The solution row discriminates: scikit-fem on the one-point rule against femkit's gauss3
    (the bug this file guards against) is out of tolerance, by orders of magnitude."""
    case = femkit.load_case(CASES / "poisson_unit_square.yaml", quadrature={"load": "gauss3"})
    same = {r.name: r for r in cc.cross_check(case)}
    assert all(r.passed for r in same.values()), same

    assemble = reference.assemble
    monkeypatch.setattr(reference, "assemble",
                        lambda mesh, kappa, f, rule=None: assemble(mesh, kappa, f, rule="barycentric"))
    other = {r.name: r for r in cc.cross_check(case)}
    assert not other["load F vs scikit-fem"].passed
    row = other["solution vs scikit-fem"]
    assert not row.passed and row.difference > 1e3 * row.tolerance
