"""Converged reference values of Cook's membrane in linear plane-strain elasticity.

Cook's membrane (the panel ``(0, 0)``, ``(48, 44)``, ``(48, 60)``, ``(0, 44)``, clamped at
``x = 0``, a total shear 1 spread evenly over the edge ``x = 48``), E = 1, plane strain, for
each Poisson ratio asked: the vertical displacement of the corner ``(48, 60)`` and of the
mid-point ``(48, 52)`` of the loaded edge, computed by scikit-fem with quartic triangles
(``ElementVector(ElementTriP4())``, ``linear_elasticity``; P4 does not lock at nu -> 1/2) on
mapped ``n x n`` meshes of the panel (the unit square's criss-cross-free grid under the bilinear
map onto the quadrilateral, whose straight edges it keeps exactly), ``n = 16, 32, 64``, and
Aitken-Richardson extrapolation of the three (the observed rate from the three values; the
clamped corners' singularities limit it to below the element's order).

Usage (a minute on one core)::

    python scripts/cook_reference.py                  # nu = 1/3 and 0.4999
    python scripts/cook_reference.py --nu 0.3 --n 8 16 32

Independent of femkit: it imports scikit-fem and NumPy only, so docs/solids.md's reference is
not femkit's own output.
"""

from __future__ import annotations

import argparse

import numpy as np


def mapped_mesh(n: int):
    """Triangles of the panel: the unit square's ``n x n`` grid (each square cut along its
    diagonal) mapped by ``x = 48 xi``, ``y = 44 xi + eta (44 - 28 xi)``."""
    from skfem import MeshTri

    m = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    xi, eta = m.p
    p = np.vstack([48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi)])
    return MeshTri(p, m.t)


def solve(n: int, nu: float, order: int = 4):
    """Vertical displacements at the corner and the mid-edge of the loaded edge."""
    import skfem
    from skfem.helpers import dot
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    elem = {2: skfem.ElementTriP2(), 3: skfem.ElementTriP3(), 4: skfem.ElementTriP4()}[order]
    mesh = mapped_mesh(n)
    basis = skfem.Basis(mesh, skfem.ElementVector(elem), intorder=2 * order)
    lam, mu = lame_parameters(1.0, nu)          # plane strain: the 2D Lame moduli unchanged
    K = linear_elasticity(lam, mu).assemble(basis)
    right = mesh.facets_satisfying(lambda x: np.isclose(x[0], 48.0))
    fb = skfem.FacetBasis(mesh, skfem.ElementVector(elem), facets=right, intorder=2 * order)

    @skfem.LinearForm
    def shear(v, w):
        return dot(np.array([0.0 * w.x[0], 0.0 * w.x[0] + 1.0 / 16.0]), v)

    f = shear.assemble(fb)
    clamped = basis.get_dofs(lambda x: np.isclose(x[0], 0.0))
    u = skfem.solve(*skfem.condense(K, f, D=clamped))
    probes = np.array([[48.0, 48.0], [60.0, 52.0]])
    values = basis.interpolator(u)(probes)        # (2 components, 2 points)
    return float(values[1, 0]), float(values[1, 1])


def richardson(a: float, b: float, c: float) -> tuple[float, float]:
    """Aitken's extrapolation of three values on meshes halved twice: ``(limit, rate)``."""
    d1, d2 = b - a, c - b
    ratio = d1 / d2
    rate = float(np.log2(abs(ratio))) if ratio > 0 else float("nan")
    return c + d2 * d2 / (d1 - d2), rate


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nu", type=float, nargs="+", default=[1.0 / 3.0, 0.4999])
    ap.add_argument("--n", type=int, nargs=3, default=[16, 32, 64])
    ap.add_argument("--order", type=int, default=4, choices=(2, 3, 4))
    args = ap.parse_args(argv)
    for nu in args.nu:
        rows = [solve(n, nu, args.order) for n in args.n]
        for n, (corner, mid) in zip(args.n, rows):
            print(f"nu = {nu:.6g}  n = {n:3d}  corner {corner:.6f}  mid-edge {mid:.6f}")
        (c, rc), (m, rm) = (richardson(*[r[k] for r in rows]) for k in (0, 1))
        print(f"nu = {nu:.6g}  extrapolated: corner {c:.4f} (rate {rc:.2f}), mid-edge {m:.4f} "
              f"(rate {rm:.2f})")


if __name__ == "__main__":
    main()
