"""The quality numbers are computed block by block; the block size changes none of them."""

import importlib

import numpy as np
import pytest

from femkit.mesh import Mesh, structured_mesh

quality_module = importlib.import_module("femkit.mesh.quality")


def _skewed():
    m = structured_mesh(9, 7)
    pts = m.points + 0.03 * np.sin(7 * m.points[:, ::-1])
    return Mesh(pts, m.triangles)


@pytest.mark.parametrize("block", [1, 5, 64], ids=["one-triangle", "five", "one-block"])
def test_block_size_changes_no_quality_number(monkeypatch, block):
    mesh = _skewed()
    whole = quality_module.quality(mesh)
    monkeypatch.setattr(quality_module, "_BLOCK", block)
    blocked = quality_module.quality(mesh)
    assert blocked.keys() == whole.keys()
    for k in whole:
        assert blocked[k] == pytest.approx(whole[k], rel=1e-15), k
    # and they are the numbers of the definition (law of cosines over all triangles at once)
    lens, ang = quality_module.side_lengths_and_angles(mesh.points[mesh.triangles])
    assert blocked["min_angle"] == np.nanmin(ang) and blocked["h_max"] == lens.max()
