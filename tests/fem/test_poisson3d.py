"""Poisson on tetrahedra end to end: patch test, rates fitted by slope, estimator effectivity."""

import numpy as np
import pytest

from femkit.fem import PoissonProblem
from femkit.fem.estimators.apply import estimate
from femkit.fem.norms import energy_error
from femkit.mesh import refine, structured_box

from ._tets import exact, grad_exact, perturbed_box, source

LEVELS = 4          # structured boxes 2^3 ... 16^3 cells (27 ... 4913 nodes)


def _slope(h, e):
    return float(np.polyfit(np.log(h), np.log(e), 1)[0])


def _solve(problem):
    return problem.solve(method="pcg", preconditioner="amg", rtol=1e-12)[0]


def test_linear_solution_reproduced_on_a_distorted_mesh():
    """Patch test: f = 0 and linear Dirichlet data give the linear function at every node."""
    m = perturbed_box(3, amount=0.4)
    g = lambda x, y, z: 1.0 + 2.0 * x - y + 0.5 * z  # noqa: E731
    u, _ = PoissonProblem(m, kappa={"left_half": 3.0, "right_half": 3.0}, f=0.0,
                          dirichlet=[(None, g)]).solve()
    np.testing.assert_allclose(u, g(*m.points.T), rtol=0, atol=1e-12)


CASES = {
    "dirichlet": dict(dirichlet=[(None, exact)]),
    "mixed": dict(dirichlet=[(["xmin", "ymin", "ymax", "zmin", "zmax"], exact)],
                  neumann=[("xmax", lambda x, y, z: grad_exact(x, y, z)[0])]),
}


@pytest.fixture(scope="module", params=list(CASES))
def sweep(request):
    """Errors and estimates on LEVELS uniformly refined boxes."""
    rows = []
    m = structured_box(2, 2, 2)
    for _ in range(LEVELS):
        prob = PoissonProblem(m, f=source, **CASES[request.param])
        u = _solve(prob)
        err = prob.errors(u, exact, grad_exact)
        energy = energy_error(m, u, grad_exact)
        rows.append(dict(h=1.0 / round(m.n_cells ** (1 / 3) / 6 ** (1 / 3)), L2=err["L2"],
                         H1=err["H1_semi"], energy=energy,
                         residual=estimate(prob, u, "residual").energy / energy,
                         zz=estimate(prob, u, "zz").energy / energy))
        m = refine(m)
    return request.param, rows


def test_rates_fitted_by_slope(sweep):
    name, rows = sweep
    h = [r["h"] for r in rows]
    rate_l2 = _slope(h, [r["L2"] for r in rows])
    rate_h1 = _slope(h, [r["H1"] for r in rows])
    print(f"{name}: L2 rate {rate_l2:.3f}, H1 rate {rate_h1:.3f}")
    assert abs(rate_l2 - 2.0) <= 0.1
    assert abs(rate_h1 - 1.0) <= 0.1


@pytest.mark.parametrize("estimator", ["residual", "zz"])
def test_effectivity_on_every_level(sweep, estimator):
    name, rows = sweep
    eff = [r[estimator] for r in rows]
    print(f"{name} {estimator}: effectivity {np.round(eff, 3).tolist()}")
    assert all(0.5 <= e <= 3.0 for e in eff)


def test_estimators_vanish_on_an_exact_linear_solution():
    m = perturbed_box(2)
    g = lambda x, y, z: x - 2.0 * y + 3.0 * z  # noqa: E731
    prob = PoissonProblem(m, f=0.0, dirichlet=[(None, g)])
    u, _ = prob.solve()
    for name in ("residual", "zz"):
        assert estimate(prob, u, name).energy < 1e-10


def test_pure_neumann_on_tetrahedra():
    """No Dirichlet data: the flux of the exact solution on all faces, mean fixed."""
    m = refine(structured_box(2, 2, 2), 2)
    normal = {"xmin": (-1, 0, 0), "xmax": (1, 0, 0), "ymin": (0, -1, 0), "ymax": (0, 1, 0),
              "zmin": (0, 0, -1), "zmax": (0, 0, 1)}
    neumann = [(side, lambda x, y, z, n=n: sum(c * g for c, g in zip(n, grad_exact(x, y, z))))
               for side, n in normal.items()]
    prob = PoissonProblem(m, f=source, dirichlet=[], neumann=neumann)
    u, _ = prob.solve()
    err = prob.errors(u, exact, grad_exact)
    ref = PoissonProblem(m, f=source, dirichlet=[(None, exact)])
    err_d = ref.errors(ref.solve()[0], exact, grad_exact)
    # the same discretisation error as the Dirichlet problem, up to a factor
    assert err["H1_semi"] <= 1.5 * err_d["H1_semi"]
    assert err["L2"] <= 3.0 * err_d["L2"]
