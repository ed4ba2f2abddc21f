"""The compiled ``cholesky`` path of the implicit steps on an elastic solid: the Newton matrix
``M + h^2 H`` (``M/h^2 + H`` scaled) written into the free-dof pattern built once from the body's
CSR pattern, refactorised on one symbolic analysis, gives the ``direct`` (SuperLU) trajectory;
and a failed Newton step hands back the run so far."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity, RayleighDamping
from femkit.dynamics.system import elastic_system
from femkit.dynamics.integrators import StepContext
from femkit.dynamics.integrators.base import NewtonStepError
from femkit.dynamics.kernels.assembly import assemble_with_forces, free_pattern
from femkit.dynamics.simulate import simulate
from femkit.mesh.structured import structured_box
from femkit.solids import ElasticBody, material
from femkit.solids.boundary import tagged_nodes
from femkit.solvers.operators import restrict
from femkit.solvers.spec import SolverSpec

ENGINES = [pytest.param("cholmod", id="cholmod"), pytest.param("cholespy", id="cholespy")]


def _engine(engine: str) -> None:
    pytest.importorskip("sksparse" if engine == "cholmod" else "cholespy",
                        reason=f"the cholesky engine {engine} is not installed")


def _beam(damped: bool):
    mesh = structured_box(4, 1, 1, (4.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e3, nu=0.3, density=1.0))
    forces = [Gravity(9.81)] + ([RayleighDamping(alpha=0.5, beta=0.01)] if damped else [])
    return body, elastic_system(body, pinned=tagged_nodes(mesh, "xmin"), forces=forces)


def test_the_compiled_newton_matrix_is_the_assembled_one():
    body, system = _beam(False)
    rng = np.random.default_rng(0)
    x = system.x0 + 0.05 * rng.standard_normal(system.x0.shape)
    x[system.pinned] = system.x0[system.pinned]
    m = np.repeat(system.mass, 3)
    pat = free_pattern(system, {})
    for fix in (None, "clamp"):
        data, f, kv = assemble_with_forces(pat, system, x, x - system.x0, 0.0, diagonal=m,
                                           kcoef=0.04, dcoef=0.0, fix=fix)
        K = system.stiffness_matrix(x, fix=fix)
        A = restrict(system.mass_matrix() + 0.04 * K, system.free_dofs).toarray()
        np.testing.assert_allclose(pat.matrix(data).toarray(), A, rtol=0, atol=1e-13 * np.abs(A).max())
        np.testing.assert_allclose(f, system.force(x, x - system.x0, rayleigh=False), atol=1e-12)
        np.testing.assert_allclose(kv.reshape(-1), K @ (x - system.x0).reshape(-1), atol=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("damped", [False, True], ids=["undamped", "rayleigh"])
@pytest.mark.parametrize("name", ["newton", "implicit_euler"])
def test_cholesky_gives_the_direct_trajectory_on_a_beam(name, damped, engine):
    _engine(engine)
    runs = {}
    for solver in ("direct", "cholesky"):
        _, system = _beam(damped)
        spec = SolverSpec("cholesky", options={"engine": engine}) if solver == "cholesky" \
            else SolverSpec("direct")
        ctx = StepContext(spec)
        runs[solver] = (simulate(system, name, 0.02, 0.3, ctx=ctx), ctx.stats)
    ref, tr = runs["direct"][0], runs["cholesky"][0]
    scale = np.abs(ref.x[-1] - ref.x[0]).max()
    assert scale > 1e-2
    assert np.abs(tr.x - ref.x).max() <= 1e-10 * scale
    stats = runs["cholesky"][1]
    if engine == "cholmod":   # one symbolic analysis for the run, every other factorisation reuses it
        assert stats["symbolic_reuses"] >= stats["factorizations"] - 1


def _collapse_system():
    """A StVK cube on rollers pushed by a dead load of 0.2 E (tests/case: the same scene)."""
    from femkit.dynamics.forces.elastic import DeadLoad
    from femkit.mesh import generate
    from femkit.solids.boundary import tagged_facets, traction_forces

    mesh = generate("unit_cube", 0.5)
    body = ElasticBody.from_mesh(mesh, material("stvk", E=1e3, nu=0.3, density=10.0))
    held = np.zeros((body.n, 3), dtype=bool)
    for axis, tag in enumerate(("xmin", "ymin", "zmin")):
        held[tagged_nodes(mesh, tag), axis] = True
    load = traction_forces(mesh.points, tagged_facets(mesh, "xmax"), [-200.0, 0.0, 0.0])
    return elastic_system(body, pinned=held, forces=[DeadLoad(load)])


def test_a_failed_newton_step_carries_its_residuals_and_the_run_so_far():
    system = _collapse_system()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(NewtonStepError) as info:
            simulate(system, "newton", 0.05, 1.0, max_backtracks=1)
    exc = info.value
    assert "line search found no decrease" in str(exc)
    assert exc.step >= 2 and exc.time == pytest.approx(0.05 * exc.step)
    assert len(exc.residuals) >= 2 and np.all(np.isfinite(exc.residuals))
    partial = exc.partial
    assert not partial.completed and partial.steps == exc.step - 1
    assert partial.times[-1] == pytest.approx(0.05 * (exc.step - 1))
    np.testing.assert_array_equal(partial.x[-1], exc.x)
