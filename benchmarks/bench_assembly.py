"""Assembly benchmark: femkit P1 stiffness + load against scikit-fem, same run, same meshes.

Run by hand:  python benchmarks/bench_assembly.py [--kmin 6] [--kmax 9] [--repeat 5] [--no-gmsh]

BLAS and numba threads are pinned to 1 before numpy is imported (the headline is
single-threaded).  Meshes: scikit-fem's ``MeshTri().refined(k)`` (2 * 4**k triangles; k = 9 has
524k, k = 10 has 2.1M) and a gmsh unit square (h = 0.05, 944 triangles) refined 5 times by
``femkit.mesh.refine`` (966,656 triangles, the ~1e6-element target of issue 2).  Both libraries
get the same points and triangles.  Printed per mesh (medians of interleaved runs: the machine is
shared, so femkit and scikit-fem alternate within each repetition):

- ``skfem 3pt``: ``Basis(mesh, ElementTriP1(), intorder=1)`` + ``asm(laplace)`` + ``asm(unit_load)``
  (scikit-fem 12's intorder=1 on triangles is its 3-point rule, its default for P1);
- ``skfem 1pt``: the same with the centroid rule passed explicitly (``quadrature=``), its
  fastest configuration;
- ``fk first``: ``assemble_stiffness`` + ``assemble_load`` on a new mesh object (the CSR pattern is
  built in the same call; numba compile excluded, it is cached on disk and reported separately);
- ``fk repeat``: the same on a mesh whose pattern is cached (a new coefficient, same mesh);
- ratios scikit-fem / femkit.

The numba compile time is measured in a subprocess with an empty temporary ``NUMBA_CACHE_DIR``
(cold), then again in a second subprocess with that cache filled (the cost of every later run).
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

_COMPILE_PROBE = """
import time
t0 = time.perf_counter()
from femkit.fem import _kernels
t1 = time.perf_counter()
_kernels.warm_up()
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def compile_times() -> tuple[tuple[float, float], tuple[float, float]]:
    """((numba import, compile) with a cold cache, (numba import, cache load) with it filled)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = []
        for _ in range(2):
            res = subprocess.run([sys.executable, "-c", _COMPILE_PROBE], env=env, capture_output=True,
                                 text=True, check=True)
            imp, comp = (float(v) for v in res.stdout.split())
            out.append((imp, comp))
    return out[0], out[1]


def meshes(kmin: int, kmax: int, gmsh: bool):
    """(label, points (n, 2), triangles (m, 3)) of the benchmark meshes, smallest first."""
    from skfem import MeshTri

    out = []
    for k in range(kmin, kmax + 1):
        sk = MeshTri().refined(k)
        out.append((f"skfem refined({k})", sk.p.T.copy(), sk.t.T.copy()))
    if gmsh:
        from femkit.mesh import generate, refine

        fine = refine(generate("unit_square", 0.05), 5)
        out.append(("gmsh h=0.05 + refine(5)", fine.points, fine.triangles))
    return sorted(out, key=lambda item: len(item[2]))


def time_case(points, triangles, repeat):
    """Interleaved timings (lists of seconds) of scikit-fem and femkit on one mesh."""
    from skfem import Basis, ElementTriP1, MeshTri, asm
    from skfem.models.poisson import laplace, unit_load

    from femkit.fem import SparsityPattern, assemble_load, assemble_stiffness
    from femkit.mesh import Mesh

    sk = MeshTri(np.ascontiguousarray(points.T), np.ascontiguousarray(triangles.T))
    centroid = (np.array([[1 / 3], [1 / 3]]), np.array([0.5]))
    cached = Mesh(points, triangles)
    SparsityPattern.for_mesh(cached)

    def skfem_3pt():
        basis = Basis(sk, ElementTriP1(), intorder=1)
        asm(laplace, basis)
        asm(unit_load, basis)

    def skfem_1pt():
        basis = Basis(sk, ElementTriP1(), quadrature=centroid)
        asm(laplace, basis)
        asm(unit_load, basis)

    def femkit_repeat():
        assemble_stiffness(cached, 2.0)
        assemble_load(cached, 1.0)

    times = {"skfem 3pt": [], "skfem 1pt": [], "fk first": [], "fk repeat": []}
    for _ in range(repeat):
        fresh = Mesh(points, triangles)  # a new mesh object: no cached pattern
        t0 = time.perf_counter()
        assemble_stiffness(fresh, 1.0)
        assemble_load(fresh, 1.0)
        times["fk first"].append(time.perf_counter() - t0)
        for name, fn in (("skfem 3pt", skfem_3pt), ("fk repeat", femkit_repeat), ("skfem 1pt", skfem_1pt)):
            t0 = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t0)
    return {k: statistics.median(v) for k, v in times.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kmin", type=int, default=6)
    ap.add_argument("--kmax", type=int, default=9)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-gmsh", action="store_true", help="skip the ~1e6-element refined gmsh mesh")
    args = ap.parse_args()

    (imp_cold, comp_cold), (imp_warm, comp_warm) = compile_times()
    from femkit.fem._kernels import warm_up

    warm_up()  # this process: compile or load from the default cache, outside the timings
    rows = []
    for label, points, triangles in meshes(args.kmin, args.kmax, not args.no_gmsh):
        t = time_case(points, triangles, args.repeat)
        rows.append((label, len(triangles), t))
        print(f"  done {label} ({len(triangles)} elements)", file=sys.stderr, flush=True)

    print(f"scikit-fem vs femkit P1 assembly (stiffness + load), 1 thread, median of {args.repeat} interleaved runs")
    print(f"{'mesh':<24} {'elements':>9} {'skfem 3pt':>9} {'skfem 1pt':>9} {'fk first':>9} {'fk repeat':>9} "
          f"{'3pt/first':>9} {'1pt/first':>9} {'3pt/rep':>8} {'1pt/rep':>8}")
    for label, m, t in rows:
        s3, s1, ff, fr = t["skfem 3pt"], t["skfem 1pt"], t["fk first"], t["fk repeat"]
        print(f"{label:<24} {m:>9} {s3:9.3f} {s1:9.3f} {ff:9.3f} {fr:9.3f} "
              f"{s3 / ff:8.1f}x {s1 / ff:8.1f}x {s3 / fr:7.1f}x {s1 / fr:7.1f}x")
    print(f"numba kernels, cold cache (subprocess, empty NUMBA_CACHE_DIR): import {imp_cold:.2f} s + "
          f"compile {comp_cold:.2f} s; cached: import {imp_warm:.2f} s + load {comp_warm:.2f} s")


if __name__ == "__main__":
    main()
