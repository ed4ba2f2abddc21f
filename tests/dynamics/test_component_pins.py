"""Per-component Dirichlet conditions in the dynamics (rollers, symmetry planes): a node held in
some components only moves freely in the others, with every registered integrator.

The scene: an elastic block standing on rollers (its face z = 0 held in z only) under a tilted
gravity. Nothing resists the tangential pull -- the roller reaction is normal to the plane and the
internal forces sum to zero -- so the block slides: its momentum along x is ``M g_x t`` exactly
(each method's update conserves it), while every held component stays exactly at 0.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.forces import Gravity
from femkit.dynamics.system import elastic_system
from femkit.dynamics.integrators import INTEGRATORS, StepContext
from femkit.dynamics.simulate import simulate
from femkit.dynamics.system import MassSpringSystem
from femkit.errors import InputError
from femkit.mesh.structured import structured_box
from femkit.solids import ElasticBody, material
from femkit.solids.boundary import tagged_nodes
from femkit.solvers.spec import SolverSpec

G = np.array([2.0, 0.0, -9.81])          # tilted gravity: tangential part 2 along x
DT, T_END = 2e-3, 0.1


def _block():
    mesh = structured_box(2, 2, 2, (1.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e3, nu=0.3, density=1.0))
    held = np.zeros((body.n, 3), dtype=bool)
    bottom = tagged_nodes(mesh, "zmin")
    held[bottom, 2] = True                # rollers: z held, x and y free
    return body, held, bottom


def _run(name, solver="direct"):
    body, held, bottom = _block()
    system = elastic_system(body, pinned=held, forces=[Gravity(G)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = simulate(system, name, DT, T_END, ctx=StepContext(SolverSpec(solver)))
    return body, system, tr, bottom


@pytest.mark.parametrize("name", sorted(INTEGRATORS))
def test_block_on_rollers_slides_under_the_tangential_gravity(name):
    body, system, tr, bottom = _run(name)
    assert tr.completed
    assert system.partially_pinned and not system.pinned.any()
    # the held components never move, bit for bit, in every frame
    assert np.all(tr.x[:, bottom, 2] == 0.0) and np.all(tr.v[:, bottom, 2] == 0.0)
    # nothing holds x: the momentum along x grows as M g_x t (round-off; projective: its sweeps
    # conserve it exactly too)
    mass = body.lumped_masses().sum()
    np.testing.assert_allclose(tr.momentum[:, 0], mass * G[0] * tr.times, rtol=1e-9,
                               atol=1e-10 * mass * G[0] * T_END)
    np.testing.assert_allclose(tr.momentum[:, 1], 0.0, atol=1e-10 * mass * G[0] * T_END)
    # the centre of mass slides by g_x t^2 / 2 (to each method's O(dt) error), the bottom face
    # with it (held in z only: not pinned; it shears a little under the tilted pull)
    m = body.lumped_masses()
    expected = 0.5 * G[0] * T_END ** 2
    centre = m @ (tr.x[-1][:, 0] - body.rest_positions[:, 0]) / m.sum()
    assert abs(centre - expected) <= 0.05 * expected
    assert np.all(tr.x[-1][bottom, 0] - body.rest_positions[bottom, 0] > 0.5 * expected)


@pytest.mark.parametrize("name", ["newton", "implicit_euler", "projective", "fast_mass_spring"])
def test_cholesky_runs_the_rollers_as_direct_does(name):
    pytest.importorskip("sksparse", reason="the cholesky solver needs scikit-sparse (CHOLMOD)")
    _, _, ref, _ = _run(name)
    _, _, tr, _ = _run(name, "cholesky")
    scale = np.abs(ref.x[-1] - ref.x[0]).max()
    assert np.abs(tr.x[-1] - ref.x[-1]).max() <= 1e-9 * scale


def test_a_component_mask_of_the_wrong_shape_is_refused():
    with pytest.raises(InputError, match=r"\(2,\) \(whole nodes\) or \(2, 2\) \(components\)"):
        MassSpringSystem(np.zeros((2, 2)), 1.0, [[0, 1]], 1.0, rest=1.0,
                         pinned=np.zeros((2, 3), dtype=bool))


def test_whole_node_pins_are_the_component_mask_with_every_component():
    x0 = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    a = MassSpringSystem(x0, 1.0, [[0, 1], [1, 2]], 5.0, pinned=[0], forces=[Gravity(1.0)])
    b = MassSpringSystem(x0, 1.0, [[0, 1], [1, 2]], 5.0,
                         pinned=np.array([[True, True], [False, False], [False, False]]),
                         forces=[Gravity(1.0)])
    assert a.pinned.tolist() == b.pinned.tolist() and a.free_dofs.tolist() == b.free_dofs.tolist()
    assert not a.partially_pinned
    ta, tb = (simulate(s, "newton", 0.05, 0.5) for s in (a, b))
    np.testing.assert_array_equal(ta.x, tb.x)
