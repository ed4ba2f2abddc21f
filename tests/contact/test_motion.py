"""Obstacles in a prescribed rigid motion (translation or keyframed path, and rotation about a
pivot): where they are at time t, that a turning one pushes a body without ever passing through
it, and that friction drags a body along with a turntable.

Every trajectory is checked frame by frame by :func:`femkit.contact.check.intersecting_pairs`
(numpy, no ipctk) and by its minimum distance (> 0), in ``_run``.
"""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

pytest.importorskip("ipctk")

from femkit.contact import Motion, body_surface, plane_obstacle  # noqa: E402
from femkit.contact.barrier import BarrierModel  # noqa: E402
from femkit.dynamics.forces import BarrierContact, Gravity  # noqa: E402
from femkit.dynamics.system import elastic_system  # noqa: E402
from femkit.solids import ElasticBody, StableNeoHookean  # noqa: E402

from _bodies import cube  # noqa: E402
from test_barrier import _run  # noqa: E402


def _body(P, T, E=1e5):
    return ElasticBody(P, T, StableNeoHookean.from_young(E, 0.3, density=1000.0))


def test_a_moving_obstacle_is_where_the_closed_form_rigid_motion_puts_it():
    # a square in the plane z = 0 turning about the z axis through (1, 0, 0) at 0.7 rad/s while
    # its pivot follows the keyframes (0, 0) -> (2, 0.4) -> (3, 0.4); the body is far away, so
    # every step's CCD-bounded moves reach the step's end place
    plane = plane_obstacle([1.0, 0.0, 0.0], [0, 0, 1], 0.5, 3)
    path = np.array([[0.0, 0, 0, 0], [2.0, 0.4, 0, 0], [3.0, 0.4, 0, 0]])
    motion = Motion(path=path, angular_velocity=np.array([0.0, 0.0, 0.7]),
                    pivot=np.array([1.0, 0.0, 0.0]))
    P, T = cube(1, 0.1, (0.0, 0.0, 5.0))
    model = BarrierModel(P, body_surface(T, 3), [replace(plane, motion=motion)])
    h = 0.25
    for k in range(12):
        model.start_motion(k * h, h)
        while model.advance(P):
            pass
    t = 12 * h
    u = np.array([0.4, 0.0, 0.0])                      # the path held after its last key
    a = 0.7 * t
    rel = plane.vertices - [1.0, 0.0, 0.0]
    turned = np.stack([np.cos(a) * rel[:, 0] - np.sin(a) * rel[:, 1],
                       np.sin(a) * rel[:, 0] + np.cos(a) * rel[:, 1], rel[:, 2]], axis=1)
    assert np.allclose(model.static, [1.0, 0.0, 0.0] + u + turned, atol=1e-12)
    mid = replace(plane, motion=motion).at(1.0)           # halfway to the second key
    assert np.allclose(mid.mean(axis=0), [1.2, 0.0, 0.0])
    # 2D: a scalar rate; a quarter turn of the segment (-1, 0)-(1, 0) about the origin
    seg = replace(plane_obstacle([0.0, 0.0], [0.0, 1.0], 1.0, 2),
                  motion=Motion(angular_velocity=np.pi / 2, pivot=np.zeros(2)))
    assert np.allclose(np.sort(seg.at(1.0)[:, 1]), [-1.0, 1.0], atol=1e-12)
    assert np.allclose(seg.at(1.0)[:, 0], 0.0, atol=1e-12)


def test_a_turning_paddle_sweeps_a_block_along_without_passing_through_it():
    # a vertical paddle (the plane x = 0 near the origin, normal +x) turning about the z axis
    # through (0, -0.3, 0.1) at 1 rad/s towards +x: it meets the block (0.01 < x < 0.11) after
    # ~0.03 s and sweeps it round; no gravity, no friction; dhat 2 mm, the paddle's 3 mm a step
    # at the block taken in several CCD-bounded moves a step
    P, T = cube(1, 0.1, (0.01, -0.05, 0.05))
    paddle = replace(plane_obstacle([0.0, 0.0, 0.1], [1, 0, 0], 0.3, 3),
                     motion=Motion(angular_velocity=np.array([0.0, 0.0, -1.0]),
                                   pivot=np.array([0.0, -0.3, 0.1])))
    force = BarrierContact(body_surface(T, 3), [paddle], dhat=2e-3)
    s = elastic_system(_body(P, T), forces=[force])
    frames, f = _run(s, 15, 0.01, tol=1e-6)    # _run: no intersection, distance > 0, each frame
    assert max(f.model.active(fr.x) for fr in frames) > 0           # it did touch
    # every block node stays on the paddle's front side (the side its normal points to)
    for fr in frames[1:]:
        turn = 1.0 * fr.t
        n = np.array([np.cos(turn), -np.sin(turn), 0.0])         # the turned normal
        assert ((fr.x - [0.0, -0.3, 0.1]) @ n).min() > 0.0
    assert frames[-1].x[:, 0].mean() > 0.06 + 0.02   # pushed forward in +x ...
    assert frames[-1].v[:, 0].mean() > 0.15          # ... and moving with the paddle (0.3 m/s)


def test_a_fast_paddle_strikes_a_resting_block_in_a_few_moves_a_step():
    # the paddle of the test above at 3 rad/s (0.9 m/s at the block, 9 mm a step: ~50 dhat at
    # the default dhat): moved alone, each CCD-bounded move gained only a fraction of the
    # barrier's gap and the first step at the block took more than the 200-move cap; the block
    # carried along with the paddle where it touches, the step takes a few moves
    P, T = cube(1, 0.1, (0.01, -0.05, 0.05))
    paddle = replace(plane_obstacle([0.0, 0.0, 0.1], [1, 0, 0], 0.3, 3),
                     motion=Motion(angular_velocity=np.array([0.0, 0.0, -3.0]),
                                   pivot=np.array([0.0, -0.3, 0.1])))
    force = BarrierContact(body_surface(T, 3), [paddle])
    s = elastic_system(_body(P, T), forces=[force])
    frames, f = _run(s, 6, 0.01, tol=1e-6)    # _run: no intersection, distance > 0, each frame
    assert f.model.stats["carries"] > 0
    assert f.model.stats["obstacle_moves"] <= 4 * 6
    for fr in frames[1:]:                     # on the paddle's front side
        n = np.array([np.cos(3.0 * fr.t), -np.sin(3.0 * fr.t), 0.0])
        assert ((fr.x - [0.0, -0.3, 0.1]) @ n).min() > 0.0
    assert frames[-1].v[:, 0].mean() > 0.5       # swept along (0.9 m/s at the block)


def test_a_rising_ball_lifts_a_cloth_lying_on_it_in_a_few_moves_a_step():
    # a ball rising at 1 m/s under a 7 x 7 cloth (1 cm a step, ~35 dhat): the cloth is carried
    # up with it, each step in a few obstacle moves (the ball alone: ~50 moves a step)
    from femkit.contact import sphere_obstacle
    from femkit.dynamics.topology import cloth_grid
    from femkit.mesh import grid_triangles

    ball = replace(sphere_obstacle([0.0, 0.0, -0.05], 0.05, 3, level=2),
                   motion=Motion(velocity=np.array([0.0, 0.0, 1.0])))
    force = BarrierContact(grid_triangles(7, 7), [ball])
    s = cloth_grid(7, 7, 0.2, 0.2, k_structural=200.0, k_shear=50.0, k_bending=0.5,
                   total_mass=0.02, pinned="none", plane="xy", origin=[-0.1, -0.1, 5e-4],
                   forces=[Gravity(9.81), force])
    frames, f = _run(s, 4, 0.01, tol=1e-6)
    assert f.model.stats["obstacle_moves"] <= 4 * 4
    for fr in frames[1:]:
        top = fr.t * 1.0                          # the ball's top
        assert top < fr.x[24, 2] < top + 0.01     # the cloth's centre node on it


def test_a_lid_pressing_a_block_through_the_table_fails_with_its_reason():
    # a lid driven down at 15 m/s onto a block resting on a static table: its place at the
    # first step's end (z = -0.05) lies past the table with the block between them -- no way
    # there without a crossing; the step fails as soon as the moves stall, saying why
    from femkit.errors import SolverError

    P, T = cube(1, 0.1, (0.01, 0.02, 1e-3))
    lid = replace(plane_obstacle([0.0, 0.0, 0.102], [0, 0, -1], 0.3, 3),
                  motion=Motion(velocity=np.array([0.0, 0.0, -15.0])))
    force = BarrierContact(body_surface(T, 3), [plane_obstacle([0.0, 0.0, 0.0], [0, 0, 1], 0.3, 3),
                                                lid])
    s = elastic_system(_body(P, T), forces=[force])
    with pytest.raises(SolverError, match="cannot make way for it .*use a smaller dt") as err:
        _run(s, 1, 0.01, tol=1e-6)
    assert "the last 20 gaining under 1%" in str(err.value)
    f = next(g for g in s.forces if isinstance(g, BarrierContact))
    assert f.model.advances < 200


def test_friction_drags_a_block_on_a_turntable_to_its_velocity():
    # a block resting at radius r on a plane turning at omega about the z axis, mu 0.5: friction
    # (mu g = 4.9 m/s^2 > omega^2 r = 1.0 m/s^2 centripetal) brings it to omega r = 0.5 m/s
    # in omega r / (mu g) ~ 0.1 s; after that it rides with the table.
    # The tolerance: smooth friction slips by a fraction of eps_v while it holds (1e-3), and
    # implicit Euler's velocity is the chord's, (x_{n+1} - x_n) / h, which turns by omega h / 2
    # from omega x r at the step's end: |v - omega x r| <= omega^2 r h / 2 + eps_v = 6e-3.
    omega, r, h, eps_v = 2.0, 0.25, 0.01, 1e-3
    P, T = cube(1, 0.06, (r - 0.03, -0.03, 5e-4))
    table = replace(plane_obstacle([0.0, 0.0, 0.0], [0, 0, 1], 0.6, 3),
                    motion=Motion(angular_velocity=np.array([0.0, 0.0, omega]),
                                  pivot=np.zeros(3)))
    force = BarrierContact(body_surface(T, 3), [table], dhat=1e-3, mu=0.5, eps_v=eps_v,
                           lagging=2)
    s = elastic_system(_body(P, T, E=1e6), forces=[Gravity(9.81), force])
    frames, f = _run(s, 25, h)
    for fr in frames[-8:]:
        c = fr.x.mean(axis=0)
        want = omega * np.array([-c[1], c[0], 0.0])             # omega x (c - pivot)
        assert np.linalg.norm(fr.v.mean(axis=0) - want) <= omega ** 2 * r * h / 2 + eps_v
        assert np.hypot(c[0], c[1]) == pytest.approx(r, rel=0.02)   # on its circle
