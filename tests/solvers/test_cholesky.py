"""The sparse Cholesky solver: equal to SuperLU on the bundled scenes' linear systems, refuses
non-SPD input with NotSPDError (no switch to LU), and reuses its symbolic analysis per pattern."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import yaml
from scipy.sparse.linalg import aslinearoperator

from femkit.dynamics import topology
from femkit.dynamics.forces import GroundContact, RayleighDamping
from femkit.errors import InputError, NotSPDError, UnknownNameError
from femkit.solvers import direct, factorize, factorize_spd, solve
from femkit.solvers.cholesky import CholeskyFactor, cholesky, clear_symbolic_cache

from .conftest import poisson_2d

pytestmark = pytest.mark.cholmod  # the cholesky solver: optional scikit-sparse

SCENES = sorted((Path(__file__).resolve().parents[2] / "cases" / "scenes").glob("*.yaml"))


def _scene_system(path: Path):
    """The scene's MassSpringSystem built through the library (topology functions), not the
    scene runner; the forces that enter the matrices (dashpots, Rayleigh, ground contact)."""
    data = yaml.safe_load(path.read_text())
    s = dict(data["system"])
    kind = s.pop("type")
    forces_spec = data.get("forces") or {}
    if isinstance(forces_spec, list):
        forces_spec = {f["type"]: f for f in forces_spec}
    forces = []
    if "rayleigh" in forces_spec:
        forces.append(RayleighDamping(**forces_spec["rayleigh"]))
    if "ground" in forces_spec:
        g = forces_spec["ground"]
        forces.append(GroundContact(g["stiffness"], g.get("height", 0.0)))
    origin = s.pop("origin", None)
    if kind == "cloth":
        return topology.cloth_grid(s.pop("nx"), s.pop("ny"), s.pop("width"), s.pop("height"),
                                   forces=forces, **s)
    if kind == "rope":
        return topology.rope(s.pop("n"), s.pop("length"), forces=forces, **s)
    if kind == "single_spring":
        return topology.single_spring(s["k"], s["m"], gravity=None, forces=forces)
    if kind == "mesh":
        from femkit.mesh import generate

        mesh = generate(s.pop("geometry"), s.pop("h"), **(s.pop("params", None) or {}))
        system = topology.mesh_springs(mesh, forces=forces, **s)
        if origin is not None:
            system.x0 = system.x0 + np.asarray(origin, float)
        return system
    raise AssertionError(f"unknown system type {kind}")


def _scene_matrices(path: Path):
    """The SPD systems the implicit integrators solve on that scene: fast mass-spring's
    ``M + h^2 L`` (n x n) and a Baraff-Witkin matrix ``M + h^2 K_clamp(x) + h D(x)`` at a
    perturbed state (compressed and stretched springs), both on the free dofs."""
    data = yaml.safe_load(path.read_text())
    h = float(eval(str(data["dt"]), {}))  # "1/30" or a number
    system = _scene_system(path)
    free_nodes = np.flatnonzero(~system.pinned)
    A_fms = (sp.diags(system.mass) + h * h * system.spring_laplacian()).tocsr()[free_nodes][:, free_nodes]
    rng = np.random.default_rng(1)
    x = system.x0 + 0.05 * np.ptp(system.x0) * rng.standard_normal(system.x0.shape)
    x[system.pinned] = system.x0[system.pinned]
    A = system.mass_matrix() + h * h * system.stiffness_matrix(x, fix="clamp") \
        + h * system.damping_matrix(x)
    f = system.free_dofs
    return {"fast_mass_spring": A_fms.tocsr(), "baraff_witkin": A.tocsr()[f][:, f].tocsr()}


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_cholesky_equals_superlu_on_bundled_scene_systems(path):
    for label, A in _scene_matrices(path).items():
        b = np.random.default_rng(2).standard_normal(A.shape[0])
        xc = cholesky(A, b, rtol=1e-12).x
        xl = direct(A, b, rtol=1e-12).x
        rel = np.linalg.norm(xc - xl) / np.linalg.norm(xl)
        assert rel <= 1e-10, (label, rel)


def test_solve_by_name_and_multiple_right_hand_sides():
    A = poisson_2d(20)
    b = np.ones(A.shape[0])
    r = solve(A, b, method="cholesky")
    assert r.converged and r.method == "cholesky" and r.reason == "direct"
    assert r.setup_time > 0 and isinstance(r.info["factorization"], CholeskyFactor)
    B = np.random.default_rng(0).standard_normal((A.shape[0], 3))
    X = r.info["factorization"].solve(B)
    np.testing.assert_allclose(A @ X, B, atol=1e-10)


@pytest.mark.parametrize("A", [
    sp.csr_matrix(np.array([[2.0, 1.0], [0.0, 2.0]])),         # not symmetric
    sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]])),         # symmetric, positive diagonal, indefinite
    sp.diags([1.0, -1.0, 2.0], format="csr"),                   # negative pivot
    sp.csr_matrix((3, 3)) + sp.diags([1.0, 0.0, 1.0]),          # singular (zero pivot)
], ids=["asymmetric", "indefinite-positive-diagonal", "negative-diagonal", "singular"])
def test_non_spd_input_raises_not_spd_error_and_is_not_switched_to_lu(A):
    b = np.ones(A.shape[0])
    with pytest.raises(NotSPDError, match="cholesky"):
        cholesky(A, b)
    with pytest.raises(NotSPDError):
        solve(A, b, method="cholesky")
    with pytest.raises(NotSPDError):
        factorize(A, spd=True)


def test_superlu_stays_available_for_what_cholesky_refuses():
    A = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))
    r = solve(A, np.array([3.0, 3.0]), method="direct")
    assert r.converged
    np.testing.assert_allclose(r.x, [1.0, 1.0])


def test_symbolic_analysis_is_reused_per_pattern():
    clear_symbolic_cache()
    A = poisson_2d(15)
    b = np.ones(A.shape[0])
    first = cholesky(A, b)
    assert first.info["symbolic_reused"] is False and first.info["symbolic_uses"] == 1
    second = cholesky(2.0 * A + sp.identity(A.shape[0]), b)     # same pattern, new values
    assert second.info["symbolic_reused"] is True and second.info["symbolic_uses"] == 2
    np.testing.assert_allclose((2.0 * A + sp.identity(A.shape[0])) @ second.x, b, atol=1e-10)
    other = cholesky(poisson_2d(16), np.ones(256))              # another pattern
    assert other.info["symbolic_reused"] is False
    # in-place refactorisation of a kept factor on the same analysis
    F = factorize_spd(A)
    uses = F.info["symbolic_uses"]
    A3 = A + 3.0 * sp.identity(A.shape[0])
    F.refactor(A3.tocsr())
    assert F.info["symbolic_uses"] == uses + 1 and F.info["symbolic_reused"]
    np.testing.assert_allclose(A3 @ F.solve(b), b, atol=1e-10)
    with pytest.raises(InputError, match="pattern"):
        F.refactor(poisson_2d(16))


@pytest.mark.parametrize("ordering", ["amd", "nesdis", "metis"])
@pytest.mark.parametrize("mode", ["supernodal", "simplicial"])
def test_every_ordering_and_mode_solves_the_cloth_systems_alike(ordering, mode):
    """Orderings and factorisation kinds change the cost, never the answer: each equals SuperLU
    to 1e-10 on both system kinds of the hanging-cloth scene, and the analysis is cached per
    (pattern, ordering, mode)."""
    clear_symbolic_cache()
    for label, A in _scene_matrices(SCENES[0]).items():
        b = np.random.default_rng(3).standard_normal((A.shape[0], 3))
        F = factorize_spd(A, ordering=ordering, mode=mode)
        assert F.info["mode"] == mode and F.info["ordering"] == ordering
        X = F.solve(b)
        ref = factorize(A).solve(b)
        assert np.linalg.norm(X - ref) <= 1e-10 * np.linalg.norm(ref), label
    other = "simplicial" if mode == "supernodal" else "supernodal"
    assert factorize_spd(A, ordering=ordering, mode=other).info["symbolic_reused"] is False
    assert factorize_spd(A, ordering=ordering, mode=mode).info["symbolic_reused"] is True


def test_bad_options_raise_named_errors():
    A = poisson_2d(5)
    with pytest.raises(UnknownNameError, match="cholesky ordering"):
        cholesky(A, np.ones(25), ordering="random")
    with pytest.raises(UnknownNameError, match="cholesky mode.*supernodal"):
        factorize_spd(A, mode="multifrontal")
    with pytest.raises(InputError, match="LinearOperator"):
        cholesky(aslinearoperator(A), np.ones(25))
    with pytest.raises(InputError, match="permc_spec"):
        factorize(A, spd=True, permc_spec="NATURAL")
