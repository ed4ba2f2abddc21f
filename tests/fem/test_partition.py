"""Partition-ready assembly: a partition's assemblies sum to the full objects."""

import numpy as np
import pytest

from femkit.errors import InputError
from femkit.fem import assemble_load, assemble_stiffness


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("parts", [2, 3, 7])
def test_partition_sums_to_full(square8, parts, backend):
    mesh = square8
    rng = np.random.default_rng(parts)
    owner = rng.integers(0, parts, mesh.n_triangles)
    kappa = lambda x, y: 1 + x * y  # noqa: E731
    f = lambda x, y: np.sin(x) + y  # noqa: E731
    K_full = assemble_stiffness(mesh, kappa)
    F_full = assemble_load(mesh, f, rule="gauss6")
    K_sum = sum(assemble_stiffness(mesh, kappa, elements=owner == p, backend=backend) for p in range(parts))
    F_sum = sum(assemble_load(mesh, f, rule="gauss6", elements=np.flatnonzero(owner == p)) for p in range(parts))
    assert K_sum.shape == K_full.shape
    assert abs(K_sum - K_full).max() <= 1e-13 * abs(K_full).max()
    assert np.allclose(F_sum, F_full, rtol=0, atol=1e-15)
    one = assemble_stiffness(mesh, kappa, elements=owner == 0)
    assert 0 < abs(one).max() and abs(one - K_full).max() > 0  # a part is not the whole


def test_per_element_kappa_array_with_subset(square8):
    mesh = square8
    kap = np.linspace(1, 2, mesh.n_triangles)
    idx = np.arange(0, mesh.n_triangles, 2)
    a = assemble_stiffness(mesh, kap, elements=idx)
    mask = np.zeros(mesh.n_triangles, bool)
    mask[idx] = True
    b = assemble_stiffness(mesh, np.where(mask, kap, 0.0) + (~mask), elements=mask)
    assert abs(a - b).max() == 0


@pytest.mark.parametrize("elements", [np.zeros(3, bool), np.array([0, 10**6]), np.array([0.5])],
                         ids=["short-mask", "out-of-range", "float-indices"])
def test_bad_element_selection(square8, elements):
    with pytest.raises(InputError):
        assemble_stiffness(square8, elements=elements)
