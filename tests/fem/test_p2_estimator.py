"""The residual estimator of P2 solutions: zero when P2 is exact, effectivity in [0.5, 3] on
every level in 2D and 3D (Dirichlet, and with Neumann fluxes), ``zz`` refused for P2."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.errors import InputError
from femkit.fem import PoissonProblem
from femkit.fem.estimators import estimate
from femkit.fem.lagrange import element_energy_error
from femkit.mesh import refine, structured_box

from .conftest import unit_square
from .test_p2_poisson import _quadratic_case


@pytest.mark.parametrize("dim", [2, 3])
def test_estimate_vanishes_when_p2_is_exact(dim):
    mesh, u, grad, f, kappa, dirichlet, neumann = _quadratic_case(dim)
    prob = PoissonProblem(mesh, kappa, f, dirichlet=dirichlet, neumann=neumann, element="P2")
    uh, _ = prob.solve("direct")
    est = estimate(prob, uh, "residual")
    assert est.indicators.shape == (mesh.n_cells,) and est.energy < 1e-9
    wrong = PoissonProblem(mesh, kappa, f + 1.0, dirichlet=dirichlet, neumann=neumann, element="P2")
    assert estimate(wrong, wrong.solve("direct")[0], "residual").energy > 1e-3   # can fail


def _effectivities(meshes, exact, grad, f, kappa, neumann, dirichlet):
    out = []
    for mesh in meshes:
        prob = PoissonProblem(mesh, kappa, f, dirichlet=dirichlet, neumann=neumann, element="P2")
        u, _ = prob.solve("direct")
        out.append(estimate(prob, u, "residual").energy / element_energy_error(mesh, u, grad, kappa))
    return np.array(out)


def test_effectivity_in_2d_with_neumann_and_a_coefficient():
    ex = lambda x, y: np.sin(np.pi * x) * np.sin(np.pi * y) + x * y
    gr = lambda x, y: (np.pi * np.cos(np.pi * x) * np.sin(np.pi * y) + y, np.pi * np.sin(np.pi * x) * np.cos(np.pi * y) + x)
    f = lambda x, y: 3.0 * 2 * np.pi ** 2 * np.sin(np.pi * x) * np.sin(np.pi * y)
    flux = lambda x, y: 3.0 * (np.pi * np.cos(np.pi * x) * np.sin(np.pi * y) + y)    # x = 1: kappa du/dx
    eff = _effectivities([refine(unit_square(2), k) for k in range(1, 5)], ex, gr, f, 3.0,
                         [("right", flux)], [(["bottom", "left", "top"], ex)])
    assert ((eff > 0.5) & (eff < 3.0)).all(), eff
    assert eff.max() / eff.min() < 1.3                      # the estimate converges at the error's rate


def test_effectivity_in_3d():
    ex = lambda x, y, z: np.sin(np.pi * x) * y * (1 + z * z)
    gr = lambda x, y, z: (np.pi * np.cos(np.pi * x) * y * (1 + z * z), np.sin(np.pi * x) * (1 + z * z),
                          np.sin(np.pi * x) * y * 2 * z)
    f = lambda x, y, z: np.pi ** 2 * np.sin(np.pi * x) * y * (1 + z * z) - np.sin(np.pi * x) * y * 2
    eff = _effectivities([structured_box(n, n, n) for n in (2, 3, 4)], ex, gr, f, 1.0, [], [(None, ex)])
    assert ((eff > 0.5) & (eff < 3.0)).all(), eff


def test_zz_is_refused_for_p2():
    prob = PoissonProblem(unit_square(2), 1.0, 1.0, element="P2")
    with pytest.raises(InputError, match="estimator 'zz' is not available for element P2; valid: residual"):
        estimate(prob, prob.solve("direct")[0], "zz")


@pytest.mark.parametrize("a", [0.0, 3.0, -0.5], ids=["no-kink", "kink-3", "kink-minus-half"])
def test_jump_term_of_a_known_kink_across_one_edge(a):
    # u = x^2 + 2y on T1 and that plus a (x + y - 1) on T2: continuous across their shared edge
    # x + y = 1, both pieces quadratic (so their P2 interpolants are exact), the normal-derivative
    # jump -a sqrt(2) along the whole edge; jump part of each cell
    # 0.5 c_J^2 / p * h_F |F| |jump|^2 = 0.5 / 24 * sqrt(2) sqrt(2) 2 a^2 = a^2 / 12
    from femkit.elements import get_element
    from femkit.fem.dofs import dof_map
    from femkit.fem.estimators.residual_p2 import residual_estimator_p2
    from femkit.mesh import Mesh

    mesh = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]),
                np.array([[0, 1, 2], [1, 3, 2]]))
    elem = get_element("P2", 2)
    dofs = dof_map(mesh, elem)
    pieces = [lambda x, y: x * x + 2 * y, lambda x, y: x * x + 2 * y + a * (x + y - 1)]
    u = np.zeros(dofs.n_dofs)
    for e, q in enumerate(pieces):
        verts = mesh.points[mesh.cells[e]]
        where = np.vstack([verts] + [(verts[i] + verts[j]) / 2 for i, j in elem.local_edges])
        u[dofs.cells[e]] = q(*where.T)
    est = residual_estimator_p2(mesh, u, kappa=1.0, f=0.0)
    np.testing.assert_allclose(est.parts["jump"], [a * a / 12] * 2, rtol=1e-12, atol=1e-14)
