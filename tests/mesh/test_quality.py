"""Quality numbers on triangles known by hand."""

import math

import numpy as np
import pytest

from femkit.mesh import Mesh, quality


def test_right_triangle_3_4_5():
    q = quality(Mesh(points=np.array([[0., 0.], [4., 0.], [0., 3.]]), triangles=np.array([[0, 1, 2]])))
    assert (q["n_points"], q["n_triangles"]) == (3, 1)
    assert q["h_max"] == pytest.approx(5.0) and q["h_min"] == pytest.approx(3.0)
    assert q["h_mean"] == pytest.approx(4.0)
    assert q["min_angle"] == pytest.approx(math.degrees(math.atan2(3, 4)))
    assert q["max_angle"] == pytest.approx(90.0)
    assert q["area"] == pytest.approx(6.0)
    # circumradius 5/2, inradius area/s = 6/6 = 1 -> R/(2r) = 1.25
    assert q["max_aspect_ratio"] == pytest.approx(1.25)


def test_equilateral_pair():
    s = math.sqrt(3) / 2
    q = quality(Mesh(points=np.array([[0., 0.], [1., 0.], [0.5, s], [1.5, s]]),
                     triangles=np.array([[0, 1, 2], [1, 3, 2]])))
    assert q["min_angle"] == pytest.approx(60.0) and q["max_angle"] == pytest.approx(60.0)
    assert q["max_aspect_ratio"] == pytest.approx(1.0)
    assert q["h_mean"] == pytest.approx(1.0) and q["area"] == pytest.approx(2 * s / 2)


def test_degenerate_has_infinite_aspect():
    q = quality(Mesh(points=np.array([[0., 0.], [1., 0.], [2., 0.]]), triangles=np.array([[0, 1, 2]])))
    assert q["max_aspect_ratio"] == math.inf and q["min_angle"] == pytest.approx(0.0)
