"""Zienkiewicz-Zhu gradient-recovery estimator (Zienkiewicz & Zhu 1987).

The recovered gradient ``G`` is continuous and piecewise linear: at each node, the area-weighted mean
of the constant gradients of the triangles around it (volume-weighted, of the tetrahedra, in 3D). The indicator is the energy norm of the
difference, integrated exactly (both are polynomials):

.. math:: \\eta_T^2 = \\int_T \\kappa_T |G - \\nabla u_h|^2 .

Where ``kappa`` jumps, the gradient jumps too; averaging across the interface would create a large
spurious indicator weighted by the large ``kappa``. So the averaging is done region by region (per
cell tag): a node on an interface gets one recovered value per region. Recovery estimators are
asymptotically exact on smooth solutions and superconvergent meshes (Zienkiewicz & Zhu 1992;
Ainsworth & Oden 2000, ch. 4) and need no constants; on boundary nodes the average is less
accurate, which is why the effectivity approaches 1 from below on coarse meshes.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from .base import ESTIMATORS, ErrorEstimate
from .geometry import element_fields


@ESTIMATORS.register("zz")
def zz_estimator(mesh, u: np.ndarray, *, kappa=1.0, f=0.0, neumann: Sequence = (),
                 dirichlet_nodes: np.ndarray | None = None) -> ErrorEstimate:
    """ZZ indicators ``eta_T`` of the P1 solution ``u``.

    ``f``, ``neumann`` and ``dirichlet_nodes`` are accepted for a common signature with
    :func:`~femkit.fem.estimators.residual_estimator` and not used (recovery looks at the
    discrete gradient only).
    """
    fl = element_fields(mesh, u, kappa)
    tri = mesh.cells
    k, dim = mesh.dim + 1, mesh.dim
    # one recovery slot per (node, region); the per-node default is one region
    _, region = np.unique(mesh.cell_tags, return_inverse=True)
    n_regions = int(region.max(initial=0)) + 1
    if n_regions == 1:
        slot, n_slots = tri, mesh.n_points
    else:
        keys = tri * n_regions + region[:, None]                                # (m, k)
        uniq, slot = np.unique(keys.ravel(), return_inverse=True)
        slot, n_slots = slot.reshape(-1, k), len(uniq)
    w = np.repeat(fl.area, k)
    wsum = np.bincount(slot.ravel(), weights=w, minlength=n_slots)
    G = np.stack([np.bincount(slot.ravel(), weights=w * np.repeat(fl.grad[:, d], k),
                              minlength=n_slots) / wsum for d in range(dim)], axis=1)
    d = G[slot] - fl.grad[:, None, :]                                          # (m, k, dim)
    # int_T phi^2 = |T| / ((d+1)(d+2)) (sum phi_i^2 + (sum phi_i)^2) for linear phi with vertex
    # values phi_i (the P1 mass matrix |T| (1 + delta_ij) / ((d+1)(d+2))): 1/12 on triangles,
    # 1/20 on tetrahedra
    sq = (d * d).sum(axis=(1, 2)) + (d.sum(axis=1) ** 2).sum(axis=1)
    eta_sq = fl.kappa * fl.area / float(k * (k + 1)) * sq
    return ErrorEstimate("zz", np.sqrt(eta_sq), {"recovery": eta_sq})
