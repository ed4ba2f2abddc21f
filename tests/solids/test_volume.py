"""Volume: stable neo-Hookean with Poisson ratio 0.45 keeps its area within 2% where Hooke
springs on the same edges lose more than 10% (the issue's acceptance item; numbers in
docs/solids.md)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from femkit.dynamics.system import elastic_system
from femkit.dynamics.forces.gravity import Gravity
from femkit.dynamics.forces.rayleigh import RayleighDamping
from femkit.dynamics.simulate import simulate
from femkit.dynamics.topology import mesh_springs
from femkit.mesh.structured import structured_mesh
from femkit.solids import ElasticBody, material


@pytest.mark.slow
def test_springs_lose_more_than_ten_percent_where_neo_hookean_keeps_two():
    """A 1 x 1 block (10 x 10 cells, all diagonals one way) on a pinned base sags under its own
    weight, damped to rest (Newton, dt = 0.5, 60 time units). The solid: stable neo-Hookean,
    E = 1, nu = 0.45, plane strain. The mass-spring body: Hooke springs on the same edges,
    k = 1.25 E, as stiff as the solid within 25% at a small load (g = 0.02 E / (rho L): sags
    compared). At g = 0.2 the spring lattice, which has no notion of area, shears and collapses
    flat (area change beyond -100%: triangles turned over), while the solid's bulk modulus
    (lambda + mu = 3.4 E) holds its area within 2%."""
    mesh = structured_mesh(10, 10, diagonal="uniform")
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1.0, nu=0.45, density=1.0))
    base = np.flatnonzero(mesh.points[:, 1] == 0.0)

    def rest_states(g):
        load = [Gravity(g), RayleighDamping(alpha=3.0)]
        pair = (elastic_system(body, pinned=base, forces=load),
                mesh_springs(mesh, k=1.25, pinned=base, forces=load))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return [simulate(s, "newton", 0.5, 60.0).x[-1] for s in pair]

    small = [1.0 - x[:, 1].max() for x in rest_states(0.02)]
    ends = rest_states(0.2)
    area0 = mesh.areas().sum()

    def area_change(x):
        e1, e2 = x[mesh.cells[:, 1]] - x[mesh.cells[:, 0]], x[mesh.cells[:, 2]] - x[mesh.cells[:, 0]]
        return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / area0 - 1.0

    change = [area_change(x) for x in ends]
    assert 0.8 < small[1] / small[0] < 1.25                 # equally stiff at a small load
    assert abs(change[0]) < 0.02                            # neo-Hookean: within 2%
    assert change[1] < -0.10                                # springs: lose more than 10%
    assert not len(body.inverted(ends[0]))
