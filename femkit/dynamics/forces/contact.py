"""Penalty contact with a ground plane and a sphere (penalty collisions: Schlögl's
lecture notes on physically based simulation).

Any penetration creates a spring force pushing the particle out: ``f = k_c p n`` with
penetration depth ``p > 0`` and outward normal ``n``; energy ``1/2 k_c p^2``. Nothing acts
on particles that do not penetrate, nor on pinned ones.
"""

from __future__ import annotations

import numpy as np

from .jacobian import nodal_block_matrix
from .base import Force, as_vector, nonnegative


class _PenaltyContact(Force):
    kind = "contact"

    def bind(self, system) -> None:
        super().bind(system)
        self._free = ~system.pinned

    def _active(self, x):
        """(nodes, depth, normal, transverse) of penetrating free nodes; transverse is the
        curvature coefficient c with K = k_c [n n^T - c (I - n n^T)] (0 for a plane)."""
        raise NotImplementedError

    def add_force(self, x, v, t, out) -> None:
        nodes, p, n, _ = self._active(x)
        if len(nodes):
            out[nodes] += (self.stiffness_value * p)[:, None] * n

    def energy(self, x) -> float:
        _, p, _, _ = self._active(x)
        return float(0.5 * self.stiffness_value * np.sum(p * p))

    def _blocks(self, x, fix):
        nodes, p, n, c = self._active(x)
        d = x.shape[1]
        if fix == "clamp":
            c = np.zeros_like(c)
        nn = n[:, :, None] * n[:, None, :]
        blocks = (1.0 + c)[:, None, None] * nn - c[:, None, None] * np.eye(d)[None]
        return nodes, self.stiffness_value * blocks

    def stiffness(self, x, fix=None):
        nodes, blocks = self._blocks(x, fix)
        if not len(nodes):
            return None
        d = x.shape[1]
        return nodal_block_matrix(x.size, d, nodes, blocks)

    def stiffness_product(self, x, d, fix=None):
        nodes, blocks = self._blocks(x, fix)
        if not len(nodes):
            return None
        out = np.zeros_like(d)
        out[nodes] = np.einsum("kab,kb->ka", blocks, d[nodes])
        return out

    def negative_bound(self, x):
        nodes, _, _, c = self._active(x)
        if not len(nodes) or not np.any(c > 0):
            return None
        e = np.zeros(x.shape[0])
        e[nodes] = self.stiffness_value * c
        return e


class GroundContact(_PenaltyContact):
    """Penalty half-space ``n . x >= height``.

    Parameters
    ----------
    stiffness : penalty stiffness ``k_c``.
    height : plane offset along ``normal``.
    normal : outward normal (normalised here); default the last axis (``+y`` in 2D, ``+z`` in 3D).

    ``K`` gets ``k_c n n^T`` on every penetrating node (PSD).
    """

    def __init__(self, stiffness: float, height: float = 0.0, normal=None):
        self.stiffness_value = nonnegative(stiffness, "ground contact stiffness")
        self.height = float(height)
        self.normal = normal

    def bind(self, system) -> None:
        super().bind(system)
        from ...errors import InputError

        if self.normal is None:
            nrm = np.zeros(system.dim)
            nrm[-1] = 1.0
        else:
            nrm = as_vector(self.normal, system.dim, "ground normal")
            length = np.linalg.norm(nrm)
            if length == 0.0:
                raise InputError("ground normal must be non-zero")
            nrm = nrm / length
        self.unit_normal = nrm

    def _active(self, x):
        depth = self.height - x @ self.unit_normal
        nodes = np.flatnonzero((depth > 0.0) & self._free)
        p = depth[nodes]
        n = np.broadcast_to(self.unit_normal, (len(nodes), x.shape[1]))
        return nodes, p, n, np.zeros(len(nodes))

    def __repr__(self) -> str:
        return f"GroundContact(stiffness={self.stiffness_value!r}, height={self.height!r}, normal={self.normal!r})"


class SphereContact(_PenaltyContact):
    """Penalty sphere (disk in 2D) of ``radius`` around ``centre``: particles are pushed out.

    With ``r = |x - c| < R``, ``n = (x - c)/r``: ``f = k_c (R - r) n`` and
    ``K = k_c [n n^T - (R/r - 1)(I - n n^T)]``; the transverse (curvature) eigenvalue is
    negative, and ``fix="clamp"`` sets it to zero. A particle exactly at the centre
    (``r < 1e-12 R``) is pushed along the last axis.
    """

    def __init__(self, centre, radius: float, stiffness: float):
        self.centre = centre
        self.radius = nonnegative(radius, "sphere radius")
        self.stiffness_value = nonnegative(stiffness, "sphere contact stiffness")

    def bind(self, system) -> None:
        super().bind(system)
        self._c = as_vector(self.centre, system.dim, "sphere centre")

    def _active(self, x):
        rel = x - self._c
        r = np.sqrt(np.einsum("nd,nd->n", rel, rel))
        nodes = np.flatnonzero((r < self.radius) & self._free)
        r = r[nodes]
        floor = 1e-12 * self.radius
        rs = np.maximum(r, floor)
        n = rel[nodes] / rs[:, None]
        at_centre = r < floor
        if at_centre.any():
            n[at_centre] = 0.0
            n[at_centre, -1] = 1.0
        return nodes, self.radius - r, n, self.radius / rs - 1.0

    def __repr__(self) -> str:
        return f"SphereContact(centre={self.centre!r}, radius={self.radius!r}, stiffness={self.stiffness_value!r})"
