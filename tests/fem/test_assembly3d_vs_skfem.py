"""P1 tetrahedra: stiffness and load against scikit-fem's MeshTet + ElementTetP1."""

import numpy as np
import pytest

from femkit.errors import InputError
from femkit.fem import assemble_load, assemble_stiffness
from femkit.fem.neumann import assemble_neumann

from ._tets import perturbed_box

skfem = pytest.importorskip("skfem")
from skfem.helpers import dot, grad  # noqa: E402


def _basis(mesh, intorder=None):
    sk = skfem.MeshTet(mesh.points.T.copy(), mesh.cells.T.copy())
    kw = {} if intorder is None else {"intorder": intorder}
    return skfem.Basis(sk, skfem.ElementTetP1(), **kw)


@skfem.BilinearForm
def _laplace(u, v, w):
    return w.kappa * dot(grad(u), grad(v))


@pytest.fixture(scope="module")
def mesh():
    return perturbed_box(3)


def _rel(a, b):
    a = a.toarray() if hasattr(a, "toarray") else a
    b = b.toarray() if hasattr(b, "toarray") else b
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("kappa", ["one", "per-region", "expression"])
def test_stiffness_equals_scikit_fem(mesh, backend, kappa):
    basis = _basis(mesh)
    if kappa == "one":
        mine, values = 1.0, np.ones(mesh.n_cells)
    elif kappa == "per-region":
        mine = {"left_half": 2.0, "right_half": 0.5}
        values = np.where(mesh.cell_tags == 1, 2.0, 0.5)
    else:
        mine = lambda x, y, z: 1.0 + x * y + z ** 2  # noqa: E731
        c = mesh.centroids()
        values = 1.0 + c[:, 0] * c[:, 1] + c[:, 2] ** 2
    kw = basis.with_element(skfem.ElementTetP0()).interpolate(values)
    K_ref = _laplace.assemble(basis, kappa=kw)
    K = assemble_stiffness(mesh, mine, backend=backend)
    assert K.shape == K_ref.shape
    assert _rel(K, K_ref) < 1e-12


@pytest.mark.parametrize("kappa", ["one", "expression"])
def test_fused_first_call_equals_scikit_fem(kappa):
    """A first compiled assembly on a fresh mesh builds the pattern and sums the stiffness in
    one pass (per-element kappa indexed by element in that pass)."""
    m = perturbed_box(3, state=4)
    from femkit.fem.sparsity import SparsityPattern

    assert SparsityPattern.cached(m) is None
    mine = 1.0 if kappa == "one" else (lambda x, y, z: 1.0 + x * y + z ** 2)
    c = m.centroids()
    values = np.ones(m.n_cells) if kappa == "one" else 1.0 + c[:, 0] * c[:, 1] + c[:, 2] ** 2
    basis = _basis(m)
    K_ref = _laplace.assemble(basis, kappa=basis.with_element(skfem.ElementTetP0()).interpolate(values))
    K = assemble_stiffness(m, mine, backend="numba")
    assert SparsityPattern.cached(m) is not None
    assert _rel(K, K_ref) < 1e-12


def test_fused_first_call_refuses_a_flat_tetrahedron():
    from femkit.errors import DegenerateMeshError
    from femkit.mesh import Mesh

    m = perturbed_box(2, state=5)
    pts = m.points.copy()
    a, b, c, d = m.cells[0]
    pts[d] = pts[a] + 0.5 * (pts[b] - pts[a]) + 0.25 * (pts[c] - pts[a])   # coplanar with a, b, c
    with pytest.raises(DegenerateMeshError):
        assemble_stiffness(Mesh(pts, m.cells), backend="numba")


def test_first_numba_assembly_builds_the_same_pattern():
    m = perturbed_box(2, state=9)
    K1 = assemble_stiffness(m, backend="numba")        # pattern built by the compiled kernel
    from femkit.fem.sparsity import SparsityPattern

    pat = SparsityPattern.from_mesh(m, backend="numpy")
    np.testing.assert_array_equal(pat.indptr, SparsityPattern.for_mesh(m).indptr)
    np.testing.assert_array_equal(pat.indices, SparsityPattern.for_mesh(m).indices)
    assert _rel(K1, assemble_stiffness(m, backend="numpy")) < 1e-14


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_centroid_load_equals_scikit_fem(mesh, backend):
    f = lambda x, y, z: np.sin(3 * x) * np.cos(y) + z ** 2  # noqa: E731
    basis = _basis(mesh, intorder=1)                    # scikit-fem's one-point rule: the centroid
    ref = skfem.LinearForm(lambda v, w: f(*w.x) * v).assemble(basis)
    assert _rel(assemble_load(mesh, f, backend=backend), ref) < 1e-12
    assert _rel(assemble_load(mesh, 2.5, backend=backend), 2.5 * skfem.LinearForm(
        lambda v, w: 1.0 * v).assemble(basis)) < 1e-12


@pytest.mark.parametrize("rule, degree", [("gauss4", 2), ("stroud8", 3), ("stroud27", 5),
                                          ("stroud64", 7)])
def test_higher_order_rules_are_exact_for_their_degree(mesh, rule, degree):
    """f of degree ``degree - 1`` times P1 is integrated exactly: equal to scikit-fem at order 8."""
    p = degree - 1
    f = lambda x, y, z: (1 + x + 2 * y - z) ** p + y * z ** (p - 1)  # noqa: E731
    ref = skfem.LinearForm(lambda v, w: f(*w.x) * v).assemble(_basis(mesh, intorder=8))
    assert _rel(assemble_load(mesh, f, rule=rule), ref) < 1e-12


def test_neumann_faces_integrate_linear_data_exactly(mesh):
    """sum_i F_i = int h ds and sum_i F_i x_i = int h x ds on the face x = 1 (h linear)."""
    h = lambda x, y, z: 1.0 + 2.0 * y - z  # noqa: E731
    F = assemble_neumann(mesh, "xmax", h)
    # on x = 1, y, z in [0, 1]: int h = 1 + 1 - 1/2, int h y = 1/2 + 2/3 - 1/4
    assert F.sum() == pytest.approx(1.5, rel=1e-13)
    assert F @ mesh.points[:, 1] == pytest.approx(0.5 + 2 / 3 - 0.25, rel=1e-13)
    assert F @ mesh.points[:, 0] == pytest.approx(1.5, rel=1e-13)
    # a constant flux on the whole boundary: its area (6 faces of the unit cube), each face once
    assert assemble_neumann(mesh, None, 2.0).sum() == pytest.approx(12.0, rel=1e-13)
    assert assemble_neumann(mesh, "boundary", 2.0).sum() == pytest.approx(12.0, rel=1e-13)


def test_two_argument_expression_on_a_3d_mesh_is_refused(mesh):
    with pytest.raises(InputError, match=r"f\(x, y, z\): the function takes \(x, y\).*3D"):
        assemble_load(mesh, lambda x, y: x + y)


def test_gmsh_msh_volume_equals_scikit_fem(tmp_path):
    """The acceptance check on a .msh volume: the Fichera corner, written and read back."""
    pytest.importorskip("gmsh")
    from femkit.mesh import generate, read_mesh, write_mesh

    write_mesh(tmp_path / "fichera.msh", generate("l_shape_3d", 0.4))
    m = read_mesh(tmp_path / "fichera.msh")
    basis = _basis(m, intorder=1)
    ones = basis.with_element(skfem.ElementTetP0()).interpolate(np.ones(m.n_cells))
    assert _rel(assemble_stiffness(m), _laplace.assemble(basis, kappa=ones)) < 1e-12
    f = lambda x, y, z: 1.0 + x * y - z  # noqa: E731
    ref = skfem.LinearForm(lambda v, w: f(*w.x) * v).assemble(basis)
    assert _rel(assemble_load(m, f), ref) < 1e-12
