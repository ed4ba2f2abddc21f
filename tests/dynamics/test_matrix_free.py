"""Matrix-free implicit steps (matrix-free CG, Baraff & Witkin 1998; Saad 2003): the operator ``A d`` equals the
assembled matrix times ``d``, one matrix-free step equals the assembled direct step to the
linear solver's tolerance, solvers that need the matrix are refused, and the scene path runs.
"""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from femkit.cli import main
from femkit.dynamics.forces import (Gravity, GroundContact, RayleighDamping, SphereContact,
                                    ViscousDamping)
from femkit.dynamics.integrators import StepContext, get_integrator
from femkit.solvers import SolverSpec
from femkit.solvers.operators import restrict
from femkit.solvers.session import MATRIX_FREE_MESSAGE
from femkit.dynamics.topology import cloth_grid
from femkit.errors import InputError

H = 0.01
RTOL = 1e-10


def _cloth(n=6, rayleigh=(0.1, 0.01)):
    """A horizontal cloth with dashpots, viscous and Rayleigh damping, ground and sphere contact,
    at a perturbed state where springs are stretched and compressed and contacts are active."""
    forces = [Gravity(9.81), RayleighDamping(*rayleigh), ViscousDamping(0.2),
              GroundContact(1e3, height=0.0), SphereContact([0.5, 0.5, 0.1], 0.3, 500.0)]
    system = cloth_grid(n, n, 1.0, 1.0, k_structural=200.0, k_shear=50.0, k_bending=10.0,
                        plane="xy", damping=0.3, forces=forces)
    rng = np.random.default_rng(7)
    x = system.x0 + 0.05 * rng.standard_normal(system.x0.shape)
    v = 0.1 * rng.standard_normal(system.x0.shape)
    v[system.pinned] = 0.0
    return system, x, v


def test_state_has_contacts_and_compressed_springs():
    """The cross-checks below cover every term: both contacts active, springs on both sides of rest."""
    system, x, _ = _cloth()
    assert np.sum(x[:, 2] < 0.0) > 3  # ground penetrated
    assert np.sum(np.linalg.norm(x - [0.5, 0.5, 0.1], axis=1) < 0.3) > 3  # inside the sphere
    length = np.linalg.norm(x[system.springs[:, 1]] - x[system.springs[:, 0]], axis=1)
    assert np.any(length < system.rest) and np.any(length > system.rest)


def _rel(a, b):
    return np.linalg.norm(np.ravel(a) - np.ravel(b)) / np.linalg.norm(np.ravel(b))


@pytest.mark.parametrize("fix", [None, "clamp", "regularize"], ids=["nofix", "clamp", "regularize"])
def test_system_products_and_diagonals_match_matrices(fix):
    system, x, _ = _cloth()
    d = np.random.default_rng(1).standard_normal(system.ndof)
    K = system.stiffness_matrix(x, fix=fix)
    assert _rel(system.stiffness_operator(x, fix=fix)(d), K @ d) < 1e-12
    np.testing.assert_allclose(system.stiffness_diagonal(x, fix=fix), K.diagonal(),
                               rtol=1e-12, atol=1e-12 * abs(K.diagonal()).max())
    D = system.damping_matrix(x)
    assert _rel(system.damping_product(x, d), D @ d) < 1e-12
    np.testing.assert_allclose(system.damping_diagonal(x), D.diagonal(), rtol=1e-12, atol=1e-15)


def _assembled_bw(system, x, fix):
    """Baraff-Witkin's matrix written out from the contract's matrices (SOFA's formula)."""
    rm, rk = system.rayleigh
    A = (1 + H * rm) * system.mass_matrix() + H * (H + rk) * system.stiffness_matrix(x, fix=fix) \
        + H * system.damping_matrix(x)
    return restrict(A, system.free_dofs)


def _assembled_newton(system, xn, x, fix):
    rm, rk = system.rayleigh
    M = system.mass_matrix()
    C = system.damping_matrix(xn) + rm * M + rk * system.stiffness_matrix(xn)
    return restrict(M + H * H * system.stiffness_matrix(x, fix=fix) + H * C, system.free_dofs)


@pytest.mark.parametrize("fix", [None, "clamp", "regularize"], ids=["nofix", "clamp", "regularize"])
@pytest.mark.parametrize("method", ["implicit_euler", "newton"])
def test_operator_matvec_equals_assembled_matrix(method, fix):
    system, x, _ = _cloth()
    integ = get_integrator(method, matrix_free=True, fix=fix)
    if method == "implicit_euler":
        op, diag, _ = integ.operator(system, x, H)
        A = _assembled_bw(system, x, fix)
    else:
        xk = x + 0.01 * np.random.default_rng(3).standard_normal(x.shape)  # iterate != x_n
        op, diag = integ.newton_operator(system, xk, H, integ.damping_operator(system, x))
        A = _assembled_newton(system, x, xk, fix)
    rng = np.random.default_rng(2)
    for _ in range(3):
        d = rng.standard_normal(len(system.free_dofs))
        assert _rel(op.matvec(d), A @ d) < 1e-12
    np.testing.assert_allclose(diag, A.diagonal(), rtol=1e-12)


SOLVERS = [pytest.param(("cg", "none"), id="cg"),
           pytest.param(("pcg", "jacobi"), id="pcg-jacobi"),
           pytest.param(("pcg", "none"), id="pcg-none")]


@pytest.mark.parametrize("solver", SOLVERS)
def test_baraff_witkin_matrix_free_step_equals_direct(solver):
    """||dv_mf - dv_direct|| <= ||A^-1|| ||r|| <= rtol ||b|| / lambda_min(A) (plus round-off)."""
    system, x, v = _cloth()
    out = {}
    for key, mf, (name, pc) in (("direct", False, ("direct", "none")), ("mf", True, solver)):
        ctx = StepContext(SolverSpec(name, pc, rtol=RTOL))
        integ = get_integrator("implicit_euler", matrix_free=mf)
        out[key] = integ.step(system, integ.start(system, x, v, 0.0, H, ctx), H, ctx)
        out[key + "_ctx"] = ctx
    assert out["mf_ctx"].stats["linear_iterations"] > 0
    assert "factorizations" not in out["mf_ctx"].stats
    A = _assembled_bw(system, x, None).toarray()
    lam_min = np.linalg.eigvalsh(A)[0]
    dv = (out["direct"].v - v).reshape(-1)[system.free_dofs]
    b = A @ dv
    bound = 2 * RTOL * np.linalg.norm(b) / lam_min + 1e-13 * np.linalg.norm(dv)
    assert np.linalg.norm(out["mf"].v - out["direct"].v) <= bound
    np.testing.assert_allclose(out["mf"].x, out["direct"].x, rtol=0, atol=H * bound)


@pytest.mark.parametrize("solver", SOLVERS)
def test_newton_matrix_free_step_equals_direct(solver):
    """Both runs converge to the minimiser of the step's energy: the iterates agree to the
    Newton stopping rule tol * L (the linear solves are exact to rtol = 1e-10)."""
    system, x, v = _cloth()
    tol = 1e-12
    res = {}
    for key, mf, (name, pc) in (("direct", False, ("direct", "none")), ("mf", True, solver)):
        ctx = StepContext(SolverSpec(name, pc, rtol=RTOL))
        integ = get_integrator("newton", matrix_free=mf, tol=tol)
        res[key] = integ.step(system, integ.start(system, x, v, 0.0, H, ctx), H, ctx)
        assert ctx.stats["newton_iterations"][0] < 50
    length = np.linalg.norm(np.ptp(x, axis=0))
    moved = np.abs(res["direct"].x - x).max()
    assert moved > 1e-4  # the step does something
    assert np.abs(res["mf"].x - res["direct"].x).max() <= 100 * tol * length


@pytest.mark.parametrize("method", ["implicit_euler", "newton"])
@pytest.mark.parametrize("solver, pc", [("direct", "none"), ("jacobi", "none"), ("pcg", "ic0"),
                                        ("pcg", "amg")],
                         ids=["direct", "jacobi-iteration", "pcg-ic0", "pcg-amg"])
def test_matrix_free_refuses_solvers_that_need_the_matrix(method, solver, pc):
    system, x, v = _cloth(4)
    integ = get_integrator(method, matrix_free=True)
    ctx = StepContext(SolverSpec(solver, pc))
    with pytest.raises(InputError, match=MATRIX_FREE_MESSAGE.replace("(", r"\(").replace(")", r"\)")):
        integ.start(system, x, v, 0.0, H, ctx)


@pytest.mark.parametrize("method", ["implicit_euler", "newton"])
def test_matrix_free_excludes_factor_reuse(method):
    with pytest.raises(InputError, match="reuse_factorization"):
        get_integrator(method, matrix_free=True, reuse_factorization=True)


# ----------------------------------------------------------------------------- scene path
SCENE = Path(__file__).parents[2] / "cases" / "scenes" / "hanging_cloth.yaml"


def _scene(tmp_path, name, integrator, linear_solver):
    data = yaml.safe_load(SCENE.read_text())
    data["system"].update(nx=6, ny=6)
    data.update(t_end=0.1, integrator=integrator, linear_solver=linear_solver)
    data["output"] = {"frames": 2}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("solver", [{"method": "cg"}, {"method": "pcg", "preconditioner": "jacobi"}],
                         ids=["cg", "pcg-jacobi"])
def test_scene_matrix_free_runs_and_matches_direct(tmp_path, solver):
    runs = {}
    for key, integ, ls in (
            ("mf", {"method": "implicit_euler", "options": {"matrix_free": True}}, solver),
            ("direct", {"method": "implicit_euler"}, {"method": "direct"})):
        path = _scene(tmp_path, key, integ, ls)
        out = tmp_path / key
        assert main(["solve", str(path), "-o", str(out), "-q"]) == 0
        runs[key] = json.loads((out / "result.json").read_text())
    assert runs["mf"]["steps"] == runs["direct"]["steps"] == 10
    assert runs["mf"]["integrator"]["options"]["matrix_free"] is True
    assert runs["mf"]["linear_solver"]["factorizations"] == 0
    assert runs["mf"]["linear_solver"]["iterations"] >= 10
    for key in ("sum_x", "sum_abs_x", "sum_v"):
        assert runs["mf"]["final_state"][key] == pytest.approx(runs["direct"]["final_state"][key],
                                                               rel=1e-8), key
    e_mf, e_dir = runs["mf"]["energy"], runs["direct"]["energy"]
    for key in e_dir:
        if isinstance(e_dir[key], float):
            assert e_mf[key] == pytest.approx(e_dir[key], rel=1e-6, abs=1e-9), key


def test_scene_matrix_free_with_direct_is_an_input_error(tmp_path, capsys):
    path = _scene(tmp_path, "bad", {"method": "implicit_euler", "options": {"matrix_free": True}},
                  {"method": "direct"})
    assert main(["solve", str(path), "-o", str(tmp_path / "bad"), "-q"]) == 2
    err = capsys.readouterr().err
    assert MATRIX_FREE_MESSAGE in err and err.startswith("femkit: error: linear_solver:")
    assert not (tmp_path / "bad").exists()  # refused at load time: nothing written
