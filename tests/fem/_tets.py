"""Shared 3D test data: perturbed structured boxes and a smooth exact solution."""

import numpy as np

from femkit.mesh import Mesh, structured_box, validate

C = 1.0 + 0.25 + 0.09


def exact(x, y, z):
    return np.exp(x + 0.5 * y - 0.3 * z)


def grad_exact(x, y, z):
    u = exact(x, y, z)
    return u, 0.5 * u, -0.3 * u


def source(x, y, z):
    """-Laplace(exact)."""
    return -C * exact(x, y, z)


def perturbed_box(n=3, amount=0.2, state=5, lengths=(1.0, 1.0, 1.0)):
    """A structured box with randomly moved interior nodes (tetrahedra of many shapes)."""
    m = structured_box(n, n, n, lengths)
    rng = np.random.default_rng(state)
    p = m.points.copy()
    L = np.asarray(lengths)
    inner = ((p > 1e-12) & (p < L - 1e-12)).all(axis=1)
    p[inner] += amount * (L / n) * rng.uniform(-0.5, 0.5, (int(inner.sum()), 3))
    return validate(Mesh(p, m.cells, cell_tags=np.where(m.centroids()[:, 0] < 0.5 * L[0], 1, 2),
                         boundary_facets=m.boundary_facets, boundary_tags=m.boundary_tags,
                         tag_names={**m.tag_names, "left_half": 1, "right_half": 2}))


def scrambled_box(n=4, state=3):
    """:func:`perturbed_box` with randomly permuted node and element numbers (an element's
    vertices far apart in memory, rows in another order than the elements)."""
    base = perturbed_box(n, state=state)
    rng = np.random.default_rng(state)
    perm = rng.permutation(base.n_points)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    return Mesh(base.points[perm], inv[base.cells][rng.permutation(base.n_cells)])
