"""P2 Poisson (PoissonProblem(element="P2")): K, F and u against scikit-fem's ElementTriP2 /
ElementTetP2 on the same mesh, exactness on quadratics (Dirichlet at edge midpoints, Neumann on
quadratic traces, regions), and the convergence rates 3 (L2) and 2 (H1) fitted by slope."""

from __future__ import annotations

import numpy as np
import pytest

from femkit.case.poisson import reference
from femkit.fem import PoissonProblem
from femkit.mesh import refine, structured_box

from ._tets import perturbed_box
from .conftest import unit_square
from .test_mass import MESHES


def _f(*x):
    return np.exp(x[0]) * (1.0 + x[1] ** 2) + (x[2] if len(x) > 2 else 0.0)


def _g(*x):
    return np.sin(x[0] + 2.0 * x[1]) + (x[2] ** 2 if len(x) > 2 else 0.0)


@pytest.mark.parametrize("shape", sorted(MESHES))
def test_K_F_u_equal_scikit_fem(shape):
    mesh = MESHES[shape]()
    kappa = 1.0 + np.random.default_rng(6).random(mesh.n_cells)
    prob = PoissonProblem(mesh, kappa, _f, dirichlet=[(None, _g)], element="P2")
    K, F = prob.assemble_matrices()
    rule = "gauss6" if mesh.dim == 2 else "sym14"        # the P2 load rule, handed to scikit-fem
    K_ref, F_ref = reference.assemble(mesh, kappa, _f, rule=rule, element="P2")
    assert abs(K - K_ref).max() <= 1e-12 * abs(K_ref).max()
    assert np.abs(F - F_ref).max() <= 1e-12 * np.abs(F_ref).max()
    fixed, values = prob.dirichlet_data()
    b = reference.basis(mesh, "P2")
    order = reference.femkit_order(mesh, b, "P2")
    theirs = np.sort(order[fixed])
    np.testing.assert_array_equal(theirs, np.sort(b.get_dofs().all()))  # the same boundary dofs
    np.testing.assert_allclose(values, _g(*b.doflocs[:, order[fixed]]), rtol=0, atol=1e-14)
    u_ref = reference.solve_direct(K_ref, F_ref, fixed, values)
    u, _ = prob.solve("direct")
    assert np.abs(u - u_ref).max() <= 1e-12 * np.abs(u_ref).max()


def _quadratic_case(dim):
    """u = quadratic, -div(kappa grad u) = const per region; kappa 2 and 2 by two region names
    (the numbers of a single coefficient), Dirichlet on some sides, Neumann flux on the others."""
    if dim == 2:
        mesh = unit_square(4)
        u = lambda x, y: 1 + x - 2 * y + x * x + 3 * x * y - 0.5 * y * y
        grad = lambda x, y: (1 + 2 * x + 3 * y, -2 + 3 * x - y)
        lap = 2.0 - 1.0
        neumann = [("right", lambda x, y: 2 * (1 + 2 * x + 3 * y)),      # n = (1, 0)
                   ("top", lambda x, y: 2 * (-2 + 3 * x - y))]           # n = (0, 1)
        dirichlet = [(["bottom", "left"], u)]
        kappa = {"west": 2.0, "east": 2.0}
    else:
        mesh = perturbed_box(2)
        u = lambda x, y, z: x * y - z * z + 2 * x * z + y
        grad = lambda x, y, z: (y + 2 * z, x + 1, -2 * z + 2 * x)
        lap = -2.0
        neumann = [("xmax", lambda x, y, z: 2 * (y + 2 * z)), ("zmax", lambda x, y, z: 2 * (-2 * z + 2 * x))]
        dirichlet = [(["xmin", "ymin", "ymax", "zmin"], u)]
        kappa = {"left_half": 2.0, "right_half": 2.0}
    return mesh, u, grad, -2.0 * lap, kappa, dirichlet, neumann


@pytest.mark.parametrize("dim", [2, 3])
def test_p2_is_exact_on_quadratics(dim):
    mesh, u, grad, f, kappa, dirichlet, neumann = _quadratic_case(dim)
    prob = PoissonProblem(mesh, kappa, f, dirichlet=dirichlet, neumann=neumann, element="P2")
    uh, _ = prob.solve("direct")
    errs = prob.errors(uh, u, grad)
    assert errs["L2"] < 1e-11 and errs["H1_semi"] < 1e-10 and errs["max_nodal"] < 1e-11
    p1 = PoissonProblem(mesh, kappa, f, dirichlet=dirichlet, neumann=neumann)   # the test can fail
    assert p1.errors(p1.solve("direct")[0], u, grad)["L2"] > 1e-4


def _rates(meshes, exact, grad, f):
    h, l2, h1 = [], [], []
    for mesh in meshes:
        prob = PoissonProblem(mesh, 1.0, f, dirichlet=[(None, exact)], element="P2")
        e = prob.errors(prob.solve("direct")[0], exact, grad)
        h.append(mesh.volumes().mean() ** (1.0 / mesh.dim))
        l2.append(e["L2"])
        h1.append(e["H1_semi"])
    return np.polyfit(np.log(h), np.log(l2), 1)[0], np.polyfit(np.log(h), np.log(h1), 1)[0]


def test_rates_3_and_2_in_2d():
    ex = lambda x, y: np.sin(np.pi * x) * np.sin(np.pi * y) + x
    gr = lambda x, y: (np.pi * np.cos(np.pi * x) * np.sin(np.pi * y) + 1, np.pi * np.sin(np.pi * x) * np.cos(np.pi * y))
    f = lambda x, y: 2 * np.pi ** 2 * np.sin(np.pi * x) * np.sin(np.pi * y)
    r_l2, r_h1 = _rates([refine(unit_square(2), k) for k in range(1, 5)], ex, gr, f)
    assert abs(r_l2 - 3) < 0.15 and abs(r_h1 - 2) < 0.1


def test_rates_3_and_2_in_3d():
    ex = lambda x, y, z: np.sin(np.pi * x) * y * (1 + z * z)
    gr = lambda x, y, z: (np.pi * np.cos(np.pi * x) * y * (1 + z * z), np.sin(np.pi * x) * (1 + z * z),
                          np.sin(np.pi * x) * y * 2 * z)
    f = lambda x, y, z: np.pi ** 2 * np.sin(np.pi * x) * y * (1 + z * z) - np.sin(np.pi * x) * y * 2
    r_l2, r_h1 = _rates([structured_box(n, n, n) for n in (2, 3, 4, 6)], ex, gr, f)
    assert abs(r_l2 - 3) < 0.25 and abs(r_h1 - 2) < 0.15


@pytest.mark.parametrize("mode, method", [("mean_zero", "direct"), ("mean_zero", "pcg"), ("pin", "direct")])
def test_pure_neumann_p2(mode, method):
    """No Dirichlet data: the P2 solution fixed by its mean (int u_h = w . u = 0 with w the P2 dof
    weights, zero at triangle vertices) or by a pinned vertex; errors modulo the constant are the
    same and fall at the rate 3 in L2."""
    from femkit.mesh import structured_mesh

    ex = lambda x, y: np.cos(np.pi * x) * np.cos(np.pi * y)                      # noqa: E731
    gr = lambda x, y: (-np.pi * np.sin(np.pi * x) * np.cos(np.pi * y),           # noqa: E731
                       -np.pi * np.cos(np.pi * x) * np.sin(np.pi * y))
    l2 = []
    for n in (8, 16):
        prob = PoissonProblem(structured_mesh(n, n), 1.0, lambda x, y: 2 * np.pi ** 2 * ex(x, y),
                              dirichlet=[], neumann=[(None, 0.0)], nullspace=mode, element="P2")
        u, res = prob.solve(method)
        assert res.converged
        if mode == "mean_zero":
            assert abs(prob.weights() @ u) < 1e-12
        l2.append(prob.errors(u, ex, gr)["L2"])
    assert 7.0 < l2[0] / l2[1] < 9.0


@pytest.mark.parametrize("dim", [2, 3])
def test_p2_pieces_over_a_partition_of_the_cells_sum_to_the_whole(dim):
    """What a distributed run computes per rank (tests/petsc): the load, the dof weights and the
    squared error integrals of P2 over the parts of a partition of the cells add up to the whole
    mesh's; each edge dof is owned by its lower node's owner (femkit.fem.distributed.partition)."""
    from femkit.fem.distributed.partition import dof_owners
    from femkit.fem.dofs import dof_map
    from femkit.fem.lagrange import dof_weights, element_error_norms, element_load
    from femkit.mesh import structured_mesh

    from femkit.mesh import Mesh

    base = structured_mesh(5, 4) if dim == 2 else structured_box(2, 3, 2)
    mesh = Mesh(base.points + 0.02 * np.sin(7.0 * base.points[:, ::-1]), base.cells)
    f = (lambda x, y: np.sin(3 * x) + y) if dim == 2 else (lambda x, y, z: np.sin(3 * x) + y * z)
    ex = (lambda x, y: np.cos(x) * y) if dim == 2 else (lambda x, y, z: np.cos(x) * y + z)
    gr = ((lambda x, y: (-np.sin(x) * y, np.cos(x))) if dim == 2
          else (lambda x, y, z: (-np.sin(x) * y, np.cos(x), 1.0 + 0 * z)))
    dofs = dof_map(mesh, "P2")
    u = np.cos(np.arange(dofs.n_dofs))
    parts = np.array_split(np.random.default_rng(0).permutation(mesh.n_cells), 3)
    whole = element_error_norms(mesh, u, ex, gr, element="P2", squared=True)
    pieces = [element_error_norms(mesh, u, ex, gr, element="P2", elements=p, squared=True) for p in parts]
    for key in ("L2", "H1_semi"):
        assert sum(p[key] for p in pieces) == pytest.approx(whole[key], rel=1e-12)
    assert max(p["max_nodal"] for p in pieces) == whole["max_nodal"]
    np.testing.assert_allclose(sum(element_load(mesh, f, "P2", elements=p) for p in parts),
                               element_load(mesh, f, "P2"), rtol=0, atol=1e-15)
    np.testing.assert_allclose(sum(dof_weights(mesh, "P2", elements=p) for p in parts),
                               dof_weights(mesh, "P2"), rtol=0, atol=1e-15)
    owner = np.arange(mesh.n_points) % 2
    owners = dof_owners(owner, dofs)
    assert np.array_equal(owners[:mesh.n_points], owner)
    assert np.array_equal(owners[mesh.n_points:], owner[np.minimum(*dofs.edge_nodes.T)])
