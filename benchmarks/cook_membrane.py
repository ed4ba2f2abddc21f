"""Cook's membrane with femkit's P1 and P2 triangles: the tables of docs/solids.md.

``--linear`` (default): linear plane strain, E = 1, total shear 1, nu = 1/3 and 0.4999, on the
bundled gmsh geometry at h = 4, 2, 1: the vertical displacement of the corner (48, 60) and of the
mid-edge (48, 52), as fractions of the converged reference (``scripts/cook_reference.py``), with
the unknowns and the solve's seconds (error against work, P1 against P2).

``--hyperelastic``: the finite-strain Cook membrane of deal.II's code gallery ("Quasi-static
finite-strain compressible elasticity", J-P. V. Pelteret and A. McBride, 2016). Its program
(``cook_membrane.cc`` since the authors' update of 2021-08-01, commit 7f3b249: ``main`` sets
``dim = 3``) solves the panel one element thick (1 mm) with every z displacement held: plane
strain with the 3D compressible neo-Hookean ``Psi = c_1 (tr b_bar - 3) + kappa/4 (J^2 - 1 - 2 ln
J)``, ``c_1 = mu/2``, ``kappa = 2 mu (1 + nu) / (3 (1 - 2 nu))``, ``b_bar = J^(-2/3) b``; mu =
0.4225 MPa, nu = 0.3 (``parameters.prm``), lengths in mm (grid scale 1e-3); a dead traction ``1 /
(16 x 1)`` along y on the right face (their "total force / surface area"), ramped over 10 time
steps; the vertical displacement **at the mid-point (48, 52) of the loaded edge** ("as stated in
the reference paper", Miehe 1994). femkit writes the energy as the designed energy
:data:`NEO_HOOKE_3D` of the three stretches (``s3 = 1``: plane strain). :data:`DEALII_2D` is the
same model with ``dim = 2`` (``b_bar = J^(-1) b``), what the program ran before 2021
(``--energy-2d``). Meshes: the panel's ``n x n`` mapped grid of their table (each quadrilateral
cut into two triangles), ``n`` = 2 .. 32 elements per edge; the mid-edge and corner (48, 60)
vertical displacements in mm beside their published Q1 and Q2 values (their README's table since
2021; the table before it, 14.33 mm for Q2, was of the corner with the earlier program).

Usage::

    python benchmarks/cook_membrane.py               # linear table (a few seconds)
    python benchmarks/cook_membrane.py --hyperelastic                 # their current model
    python benchmarks/cook_membrane.py --hyperelastic --energy-2d     # the dim = 2 energy
    python benchmarks/cook_membrane.py --check-skfem   # femkit's P2 solution in scikit-fem's weak form
"""

from __future__ import annotations

import argparse
import time

import numpy as np

#: converged vertical displacements (corner, mid-edge), scikit-fem P4 + Aitken
REFERENCE = {1.0 / 3.0: (22.610, 21.525), 0.4999: (19.428, 18.512)}
#: deal.II code gallery README (since 2021-08-01), y-displacement of the mid-edge (48, 52) in mm
#: at 2, 4, ..., 64 elements per edge (3D program, one element thick, z held)
DEALII = {"Q1": (8.638, 12.07, 13.86, 14.49, 14.67, 14.72),
          "Q2": (14.30, 14.65, 14.71, 14.73, 14.74, 14.74)}
#: deal.II's energy with dim = 2 (their program before 2021), in three stretches: at s3 = 1 it is theirs
DEALII_2D = "mu/2*((s1**2 + s2**2 + s3**2 - 1)/J - 2) + kappa/4*(J**2 - 1 - 2*log(J))"
#: their model (dim = 3, b_bar = J^(-2/3) b); at s3 = 1 the plane strain of their z-held slab
NEO_HOOKE_3D = "mu/2*(J**(-2/3)*(s1**2 + s2**2 + s3**2) - 3) + kappa/4*(J**2 - 1 - 2*log(J))"


def mapped_mesh(n: int):
    """The panel's ``n x n`` grid under the bilinear map of the unit square (as deal.II's
    ``subdivided_hyper_rectangle`` + transform), each cell cut along one diagonal, with the
    tags ``clamped`` (x = 0) and ``loaded`` (x = 48)."""
    from femkit.mesh import Mesh
    from femkit.mesh.structured import grid_triangles

    t = np.linspace(0.0, 1.0, n + 1)
    xi, eta = (a.ravel() for a in np.meshgrid(t, t, indexing="xy"))
    pts = np.column_stack([48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi)])
    cells = grid_triangles(n + 1, n + 1)
    k = np.arange(n)
    left = np.column_stack([(k + 1) * (n + 1), k * (n + 1)])
    right = np.column_stack([k * (n + 1) + n, (k + 1) * (n + 1) + n])
    return Mesh(pts, cells, boundary_facets=np.vstack([left, right]),
                boundary_tags=np.repeat([1, 2], n), tag_names={"clamped": 1, "loaded": 2})


def solve(mesh, mat, element: str, traction, load_steps: int = 1):
    """The static equilibrium; returns ``(body, u, seconds)``."""
    from femkit.solids import Dirichlet, ElasticBody, solve_static, tagged_facets, traction_forces
    from femkit.solids.quadratic import facet_nodes

    def facets(tag):
        f = tagged_facets(mesh, tag)
        return f if element == "P1" else facet_nodes(mesh, f, element)

    t0 = time.perf_counter()
    body = ElasticBody.from_mesh(mesh, mat, element)
    bc = Dirichlet(body.n, 2).fix(np.unique(facets("clamped")))
    f = traction_forces(body.rest_positions, facets("loaded"), traction)
    u = solve_static(body, bc, f, load_steps=load_steps).u
    return body, u, time.perf_counter() - t0


def _at(body, point) -> int:
    return int(np.flatnonzero(np.all(np.isclose(body.rest_positions, point), axis=1))[0])


def linear_table() -> None:
    from femkit.mesh import generate
    from femkit.solids import material

    print("| nu | h | element | unknowns | corner (48, 60) | mid-edge (48, 52) | solve s |")
    print("|---|---|---|---|---|---|---|")
    for nu, (rc, rm) in REFERENCE.items():
        for h in (4.0, 2.0, 1.0):
            mesh = generate("cook_membrane", h)
            for element in ("P1", "P2"):
                mat = material("linear", E=1.0, nu=nu)
                solve(mesh, mat, element, [0.0, 1.0 / 16.0])           # compile, caches
                body, u, sec = solve(mesh, mat, element, [0.0, 1.0 / 16.0])
                c, m = u[_at(body, (48.0, 60.0)), 1], u[_at(body, (48.0, 52.0)), 1]
                print(f"| {nu:.4g} | {h:g} | {element} | {body.ndof:,} | {c:.4f} ({c / rc:.1%}) "
                      f"| {m:.4f} ({m / rm:.1%}) | {sec:.3f} |")


def hyperelastic_table(sizes, energy: str = NEO_HOOKE_3D) -> None:
    from femkit.solids.materials import EnergyMaterial

    mu, nu = 0.4225, 0.3
    kappa = 2.0 * mu * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))
    mat = EnergyMaterial.from_energy({"W": energy}, {"mu": mu, "kappa": kappa})
    print(f"W = {energy}")
    print("| elements per edge | femkit P1 mid-edge | femkit P2 mid-edge | P2 dofs | deal.II Q1 "
          "| deal.II Q2 | femkit P1 / P2 corner |")
    print("|---|---|---|---|---|---|---|")
    for n in sizes:
        k = int(round(np.log2(n))) - 1
        row = []
        for element in ("P1", "P2"):
            body, u, _ = solve(mapped_mesh(n), mat, element, [0.0, 1.0 / 16.0], load_steps=10)
            row.append((u[_at(body, (48.0, 52.0)), 1], u[_at(body, (48.0, 60.0)), 1], body.ndof))
        ref = [f"{DEALII[q][k]:.2f}" if 0 <= k < len(DEALII[q]) else "-" for q in ("Q1", "Q2")]
        print(f"| {n} | {row[0][0]:.2f} | {row[1][0]:.2f} | {row[1][2]:,} | {ref[0]} | {ref[1]} "
              f"| {row[0][1]:.2f} / {row[1][1]:.2f} |", flush=True)


def skfem_residual(n: int = 8) -> None:
    """An independent check of femkit's nonlinear P2 solid: femkit's P2 solution of deal.II's 2D
    model on the ``n x n`` mapped mesh, put into scikit-fem's ``ElementVector(ElementTriP2())``
    (dofs matched by position) and the weak form ``int P(F) : grad v = int t . v`` assembled by
    scikit-fem with ``P = mu (F/J - tr(C)/(2J) F^-T) + kappa/2 (J^2 - 1) F^-T`` written by hand:
    the residual relative to the load, with femkit's 3-point rule and with a 6th-order one."""
    import skfem
    from skfem.helpers import ddot, grad

    from femkit.solids.materials import EnergyMaterial

    mu, nu = 0.4225, 0.3
    kappa = 2.0 * mu * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))
    mat = EnergyMaterial.from_energy({"W": DEALII_2D}, {"mu": mu, "kappa": kappa})
    mesh = mapped_mesh(n)
    body, u, _ = solve(mesh, mat, "P2", [0.0, 1.0 / 16.0], load_steps=10)
    m = skfem.MeshTri(mesh.points.T.copy(), mesh.cells.T.copy())
    e = skfem.ElementVector(skfem.ElementTriP2())

    @skfem.LinearForm
    def internal(v, w):
        F = grad(w["u"]) + np.eye(2)[:, :, None, None]
        J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
        finv_t = np.array([[F[1, 1], -F[1, 0]], [-F[0, 1], F[0, 0]]]) / J
        P = mu * (F / J - (F ** 2).sum(axis=(0, 1)) / (2 * J) * finv_t) \
            + kappa / 2 * (J ** 2 - 1) * finv_t
        return ddot(P, grad(v))

    @skfem.LinearForm
    def load(v, w):
        return v[1] / 16.0

    fb = skfem.FacetBasis(m, e, facets=m.facets_satisfying(lambda x: np.isclose(x[0], 48.0)),
                          intorder=4)
    f = load.assemble(fb)
    for order in (2, 6):
        basis = skfem.Basis(m, e, intorder=order)
        where = {(round(p[0], 9), round(p[1], 9), c): i for i, (p, c) in
                 enumerate(zip(basis.doflocs.T, np.tile([0, 1], basis.N // 2)))}
        U = np.zeros(basis.N)
        for i, p in enumerate(body.rest_positions):
            for c in range(2):
                U[where[(round(p[0], 9), round(p[1], 9), c)]] = u[i, c]
        r = internal.assemble(basis, u=basis.interpolate(U)) - f
        free = np.setdiff1d(np.arange(basis.N),
                            basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).flatten())
        print(f"n = {n}, scikit-fem intorder {order}: |residual| / |load| = "
              f"{np.linalg.norm(r[free]) / np.linalg.norm(f):.3e}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hyperelastic", action="store_true")
    ap.add_argument("--sizes", type=int, nargs="+", default=[2, 4, 8, 16, 32])
    ap.add_argument("--energy-2d", action="store_true",
                    help="the dim = 2 form of the energy (their program before 2021) instead of dim = 3")
    ap.add_argument("--check-skfem", action="store_true",
                    help="femkit's hyperelastic P2 solution in scikit-fem's own weak form")
    args = ap.parse_args(argv)
    if args.check_skfem:
        skfem_residual()
    elif args.hyperelastic:
        hyperelastic_table(args.sizes, DEALII_2D if args.energy_2d else NEO_HOOKE_3D)
    else:
        linear_table()


if __name__ == "__main__":
    main()
