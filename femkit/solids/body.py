"""An elastic body: P1 or P2 elements of a mesh, a material per region, energy/gradient/Hessian.

``ElasticBody(points, cells, material)`` precomputes the rest data once
(:func:`~femkit.solids.kinematics.rest_shape`) and, on the first Hessian, the CSR pattern
(:class:`~femkit.fem.sparsity.BlockPattern`); each evaluation is one compiled pass per material
group (:mod:`femkit.elements.compiled`). Positions are node-major ``(n, d)`` arrays, the flat
dof index ``i*d + a`` as in :mod:`femkit.dynamics`. With ``element="P2"`` the nodes are the
mesh's vertices followed by its edge midpoints and every cell is evaluated at the points of a
quadrature rule (:mod:`femkit.solids.quadratic`).

>>> import numpy as np
>>> from femkit.solids.materials import StableNeoHookean
>>> body = ElasticBody([[0., 0.], [1., 0.], [0., 1.]], [[0, 1, 2]], StableNeoHookean(1.0, 1.0))
>>> body.energy(body.rest_positions)
0.0
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, SolverError
from .kinematics import RestShape, deformation_gradients, rest_shape
from .materials.base import Material

__all__ = ["ElasticBody", "point_tangent"]


def point_tangent(material: Material, F, *, project: bool = False):
    """``(psi, P, dP/dF)`` of ``material`` at one deformation gradient ``F`` (``d x d``);
    ``dP/dF`` as a ``d^2 x d^2`` matrix over row-major ``vec(F)``, projected to PSD (eigenvalues
    clamped at 0, Teran et al. 2005) when ``project``."""
    F = np.ascontiguousarray(F, dtype=float)
    d = F.shape[0]
    P, lam, Q = np.zeros((d, d)), np.zeros(d * d), np.zeros((d * d, d, d))
    psi = material.kernels().point(material.code, F, material.params(), 2, P, lam, Q, np.zeros((6, d, d)),
                np.zeros((2, d)))
    if project:
        lam = np.maximum(lam, 0.0)
    q = Q.reshape(d * d, d * d)
    return float(psi), P, (q.T * lam) @ q


class ElasticBody:
    """Elastic body of P1 or P2 elements (triangles in plane strain, or tetrahedra).

    Parameters
    ----------
    points : (n, d) rest positions, ``d`` = 2 or 3.
    cells : (m, d+1) int, positively oriented (``det Dm > 0``).
    material : Material, or a mapping ``{region: Material}`` with ``cell_tags`` (region: tag id,
        or tag name when ``tag_names`` is given); every cell must get a material.
    cell_tags : (m,) int, optional.
    tag_names : mapping name -> tag id, optional.
    element : ``"P1"`` (default) or ``"P2"`` (:data:`femkit.elements.ELEMENTS`): P2 adds a node
        at every edge midpoint (:attr:`rest_positions` holds them after the vertices).
    mesh : the :class:`femkit.mesh.Mesh` of ``points`` and ``cells``, optional (P2 numbers its
        edges; :meth:`from_mesh` passes it).

    Raises
    ------
    DegenerateMeshError
        Inverted or zero-volume elements in the rest mesh (named).
    InputError
        Bad shapes, unknown region, cells without a material.
    UnknownNameError
        An unknown ``element`` (the valid ones listed).
    """

    def __init__(self, points, cells, material, *, cell_tags=None, tag_names: Mapping | None = None,
                 element: str = "P1", mesh=None):
        if element == "P1":
            self.rest: RestShape = rest_shape(points, cells)
            self.rest_positions = np.ascontiguousarray(points, dtype=float)
        else:
            from ..elements import get_element
            from .quadratic import node_positions, quadratic_rest

            if mesh is None:
                from ..mesh import Mesh

                rest_shape(points, cells)               # the shapes and orientation, checked first
                mesh = Mesh(points, cells)
            get_element(element, mesh.dim)              # UnknownNameError listing the valid ones
            self.rest = quadratic_rest(mesh, element)
            self.rest_positions = node_positions(mesh, element)
        self.element = self.rest.element
        self.n, self.dim = self.rest_positions.shape
        self.ndof = self.n * self.dim
        m = self.rest.n_cells
        if isinstance(material, Material):
            groups = [(np.arange(m, dtype=np.int64), material)]
        elif isinstance(material, Mapping):
            if cell_tags is None:
                raise InputError("materials per region need cell_tags")
            tags = np.asarray(cell_tags)
            if tags.shape != (m,):
                raise InputError(f"cell_tags must have {m} entries, got shape {tags.shape}")
            names = dict(tag_names or {})
            covered = np.zeros(m, dtype=bool)
            groups = []
            for region, mat in material.items():
                if not isinstance(mat, Material):
                    raise InputError(f"region {region!r}: not a femkit material: {mat!r}")
                tag = names.get(region, region) if isinstance(region, str) else region
                if isinstance(tag, str):
                    raise InputError(f"unknown region {region!r}; valid regions: "
                                     f"{', '.join(sorted(names)) or '(none named)'}")
                sel = np.flatnonzero(tags == tag)
                covered[sel] = True
                groups.append((sel.astype(np.int64), mat))
            if not covered.all():
                raise InputError(f"{int((~covered).sum())} cells have no material, first "
                                 f"{int(np.flatnonzero(~covered)[0])} (tag {tags[~covered][0]})")
        else:
            raise InputError(f"material must be a femkit material or a mapping, got {material!r}")
        self.groups = groups
        self._pattern = None

    @classmethod
    def from_mesh(cls, mesh, material, element: str = "P1") -> "ElasticBody":
        """The body of a :class:`femkit.mesh.Mesh` (triangles: plane strain; tetrahedra);
        ``material`` one :class:`Material` or ``{region name or tag: Material}``; ``element``
        ``"P1"`` or ``"P2"``."""
        return cls(mesh.points, mesh.cells, material, cell_tags=mesh.cell_tags,
                   tag_names=mesh.tag_names, element=element, mesh=mesh)

    # ------------------------------------------------------------------ data
    @property
    def materials(self) -> list[Material]:
        return [mat for _, mat in self.groups]

    @property
    def pattern(self):
        """The CSR pattern of the Hessian (built on first use, then kept)."""
        if self._pattern is None:
            from ..fem.sparsity import BlockPattern

            self._pattern = BlockPattern(self.rest.cells, self.n, self.dim)
        return self._pattern

    def density(self) -> np.ndarray:
        """Density per element, ``(m,)``."""
        rho = np.empty(self.rest.n_cells)
        for elems, mat in self.groups:
            rho[elems] = mat.density
        return rho

    def lumped_masses(self) -> np.ndarray:
        """Lumped masses ``(n,)``, all positive: P1 row sums (each element's ``rho vol`` split
        equally among its ``d + 1`` vertices); P2 HRZ diagonal scaling
        (:func:`femkit.fem.mass.lumping_weights`: a triangle's vertex gets 3/57 of its mass, an
        edge node 16/57; a tetrahedron's 1/36 and 4/27), where row sums would give zero or
        negative vertex masses."""
        if self.element == "P1":
            w = np.repeat(self.density() * self.rest.volumes / (self.dim + 1), self.dim + 1)
            return np.bincount(self.rest.cells.ravel(), weights=w, minlength=self.n)
        from ..elements import get_element
        from ..fem.mass import lumping_weights

        share = lumping_weights(get_element(self.element, self.dim))
        w = (self.density() * self.rest.volumes)[:, None] * share[None, :]
        return np.bincount(self.rest.cells.ravel(), weights=w.ravel(), minlength=self.n)

    def inverted(self, x) -> np.ndarray:
        """Ids of the elements with ``det F <= 0`` at ``x`` (inverted or flat; P2: at any of
        their quadrature points)."""
        bad = np.flatnonzero(np.linalg.det(self.deformation_gradients(x)) <= 0.0)
        return np.unique(bad // self.rest.n_points)

    def deformation_gradients(self, x) -> np.ndarray:
        return deformation_gradients(self._state(x), self.rest)

    def _state(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.shape != (self.n, self.dim):
            if x.shape == (self.ndof,):
                return np.ascontiguousarray(x.reshape(self.n, self.dim))
            raise InputError(f"positions must have shape ({self.n}, {self.dim}), got {x.shape}")
        return np.ascontiguousarray(x)

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, x, level: int = 2, *, project: bool = False, stress: np.ndarray | None = None):
        """One compiled pass: ``(element_energies (m,), gradient (n, d) or None, hessian CSR or
        None, negative (m,) or None)``; ``level`` 0, 1 or 2 as in the kernel. ``negative[e]``
        bounds the negative part of element ``e``'s unprojected Hessian (see
        :meth:`negative_bound`). ``stress``: an ``(m, d, d)`` array to receive the first
        Piola-Kirchhoff stress per element (``level >= 1``); P2: ``(m q, d, d)``, one per
        quadrature point."""
        x = self._state(x)
        m = self.rest.n_cells
        energy = np.zeros(m)
        grad = np.zeros((self.n, self.dim))
        neg = np.zeros(m)
        if level >= 2:
            pat = self.pattern
            data, slots, indptr = np.zeros(pat.nnz), pat.node_slots, pat.node_indptr
        else:
            data, slots, indptr = np.zeros(0), np.zeros((0, 0), np.int64), np.zeros(1, np.int64)
        r = self.rest
        P = np.zeros((0, self.dim, self.dim)) if stress is None else stress
        for elems, mat in self.groups:
            if r.weights is None:
                mat.kernels().element_pass(mat.code, x, r.cells, r.gradients, r.volumes, elems,
                                           mat.params(), int(level), bool(project), slots, indptr,
                                           energy, grad, data, neg, P)
            else:
                mat.kernels().element_pass_points(
                    mat.code, x, r.cells, r.gradients, r.weights, r.n_points, elems, mat.params(),
                    int(level), bool(project), slots, indptr, energy, grad, data, neg, P)
        if not np.all(np.isfinite(energy)):
            bad = np.flatnonzero(~np.isfinite(energy))
            raise SolverError(f"elastic energy not finite on {len(bad)} elements, first {int(bad[0])}")
        return (energy, grad if level >= 1 else None,
                self.pattern.matrix(data) if level >= 2 else None, neg if level >= 2 else None)

    def energy(self, x) -> float:
        """Total elastic energy."""
        return float(self.evaluate(x, 0)[0].sum())

    def gradient(self, x) -> np.ndarray:
        """``dE/dx``, ``(n, d)`` (minus the elastic force)."""
        return self.evaluate(x, 1)[1]

    def hessian(self, x, *, project: bool = False) -> sp.csr_matrix:
        """``d^2E/dx^2`` (CSR ``nd x nd``); element-wise PSD-projected when ``project``."""
        return self.evaluate(x, 2, project=project)[2]

    def stresses(self, x) -> np.ndarray:
        """First Piola-Kirchhoff stress ``P = dpsi/dF`` per element, ``(m, d, d)`` (P2: per
        quadrature point, ``(m q, d, d)``, row ``e q + k``)."""
        P = np.zeros((self.rest.n_cells * self.rest.n_points, self.dim, self.dim))
        self.evaluate(x, 1, stress=P)
        return P

    def element_fields(self, x) -> dict:
        """Per-element output fields at ``x``: ``principal_stretches`` ``(m, d)`` (signed, the
        invertible SVD), ``J`` ``(m,)`` (``det F``), ``cauchy`` ``(m, d, d)``
        (``sigma = P F^T / J``) and ``von_mises`` ``(m,)`` of the in-plane (2D) or full (3D)
        Cauchy stress, ``sqrt(3/2 |dev sigma|^2)`` (in 2D the plane-strain ``sigma_zz`` is left
        out). Elements with ``J <= 0`` get NaN in ``cauchy`` and ``von_mises`` (their Cauchy
        stress is undefined); :meth:`inverted` names them. P2: each field is the mean over the
        cell's quadrature points (weighted: ``sum volumes J`` is the deformed volume by the
        rule), computed point by point first."""
        from .kinematics import invertible_svd

        F = self.deformation_gradients(x)
        _, s, _ = invertible_svd(F)
        P = self.stresses(x)
        J = np.linalg.det(F)
        ok = J > 0.0
        sigma = np.full_like(P, np.nan)
        sigma[ok] = np.einsum("mab,mcb->mac", P[ok], F[ok]) / J[ok, None, None]
        dev = sigma - np.einsum("maa->m", sigma)[:, None, None] / self.dim * np.eye(self.dim)
        vm = np.sqrt(1.5 * np.einsum("mab,mab->m", dev, dev))
        fields = {"principal_stretches": s, "J": J, "cauchy": sigma, "von_mises": vm}
        q = self.rest.n_points
        if q == 1:
            return fields
        share = (self.rest.weights / np.repeat(self.rest.volumes, q)).reshape(-1, q)
        return {k: np.einsum("mq,mq...->m...", share, v.reshape(-1, q, *v.shape[1:]))
                for k, v in fields.items()}

    def negative_bound(self, x) -> np.ndarray:
        """Per-node ``e_i >= 0`` with ``z^T H(x) z >= -sum_i e_i |z_i|^2``: each element's
        ``vol sum |lam_k^-| |g|_F^2`` (negative eigenvalues of ``dP/dF``; ``|w_k| <= |g|_F``)
        added to its vertices."""
        neg = self.evaluate(x, 2)[3]
        return np.bincount(self.rest.cells.ravel(), weights=np.repeat(neg, self.rest.cells.shape[1]),
                           minlength=self.n)
