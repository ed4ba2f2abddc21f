"""Size and shape metrics of a triangle mesh.

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> q = quality(Mesh(points=np.array([[0., 0.], [1., 0.], [0., 1.]]), triangles=np.array([[0, 1, 2]])))
>>> round(q["min_angle"], 6), round(q["max_aspect_ratio"], 6)
(45.0, 1.207107)
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh


def quality(mesh: Mesh) -> dict:
    """Mesh size and shape numbers.

    Returns
    -------
    dict with
        ``n_points``, ``n_triangles``;
        ``h_max`` (longest edge), ``h_min`` (shortest edge), ``h_mean`` (mean over unique edges);
        ``min_angle``, ``max_angle`` (degrees, over all triangles);
        ``max_aspect_ratio``, ``mean_aspect_ratio``: circumradius / (2 inradius), 1 for an
        equilateral triangle, infinite for a degenerate one;
        ``area`` (total area).
    """
    from .edges import edges

    p = mesh.points[mesh.triangles]                      # (m, 3, 2)
    e = p[:, [2, 0, 1]] - p[:, [1, 2, 0]]                # edge opposite vertex k
    lens = np.sqrt(np.einsum("ijk,ijk->ij", e, e))       # (m, 3)
    area = mesh.areas()
    edge_nodes, _ = edges(mesh)
    d = mesh.points[edge_nodes[:, 1]] - mesh.points[edge_nodes[:, 0]]
    unique_len = np.hypot(d[:, 0], d[:, 1])
    # angle at vertex k from the law of cosines (a = opposite side)
    a, b, c = lens, lens[:, [1, 2, 0]], lens[:, [2, 0, 1]]
    with np.errstate(divide="ignore", invalid="ignore"):
        cosang = np.clip((b * b + c * c - a * a) / (2.0 * b * c), -1.0, 1.0)
        ang = np.degrees(np.arccos(cosang))
        s = 0.5 * lens.sum(axis=1)
        circum = lens.prod(axis=1) / (4.0 * area)
        inr = area / s
        aspect = np.where(area > 0, circum / (2.0 * inr), np.inf)
    return {
        "n_points": mesh.n_points,
        "n_triangles": mesh.n_triangles,
        "h_max": float(lens.max()),
        "h_min": float(lens.min()),
        "h_mean": float(unique_len.mean()),
        "min_angle": float(np.nanmin(ang)),
        "max_angle": float(np.nanmax(ang)),
        "max_aspect_ratio": float(aspect.max()),
        "mean_aspect_ratio": float(aspect.mean()),
        "area": float(area.sum()),
    }
