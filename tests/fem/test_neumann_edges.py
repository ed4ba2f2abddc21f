"""Neumann loads integrate over each boundary edge once, whatever tags name it.

Generated meshes tag every boundary edge twice (its named part and ``boundary``), so the
union of tags must not count an edge twice: the total flux ``int h ds`` of ``h = 1`` is the
length of the boundary covered, checked against the perimeter by hand.
"""

import numpy as np
import pytest

from femkit.fem import assemble_neumann
from femkit.mesh import Mesh, generate


@pytest.fixture(scope="module")
def square():
    return generate("unit_square", h=0.25)


@pytest.mark.parametrize("tags, length", [
    (["boundary"], 4.0),
    (["boundary", "left"], 4.0),
    (["left", "left"], 1.0),
    (["left", "bottom"], 2.0),
    (None, 4.0),
], ids=["boundary", "boundary+left", "left-twice", "left+bottom", "none-whole-boundary"])
def test_total_unit_flux_is_the_covered_length(square, tags, length):
    assert assemble_neumann(square, tags, 1.0).sum() == pytest.approx(length, rel=1e-13)


def test_none_means_whole_topological_boundary_without_tagged_edges(square):
    bare = Mesh(square.points, square.triangles)  # no boundary edges recorded at all
    F = assemble_neumann(bare, None, lambda x, y: 1 + 0 * x)
    np.testing.assert_allclose(F, assemble_neumann(square, ["boundary"], 1.0), rtol=0, atol=1e-15)
