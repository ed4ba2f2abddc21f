"""Building the implicit methods' free-dof pattern (run by hand):
``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_free_pattern.py [--repeat 7]``.

:class:`femkit.dynamics.kernels.assembly.FreePattern` is built by the one assembly stack
(:mod:`femkit.fem.sparsity`: springs as 2-node cells of a node-level pattern, node pairs as
``d x d`` blocks, a force's structure joined by a merge of sorted keys, held dofs dropped with a
slot map). Its peer, in the same run, is the construction it replaced: ``np.unique`` over the
``(row, column)`` keys of every dof-level entry (spring blocks, node diagonal blocks, structure)
restricted to the free dofs. Scenes: Liu's 81 x 81 cloth (38,558 springs, two corners pinned)
and a 24 x 12 x 12 Kuhn box of neo-Hookean tetrahedra (an elastic body's structure, one face
pinned). Process CPU time, the two builds interleaved, median over ``--repeat``; the peer's
indices and the pattern's are checked equal first.
"""

from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from femkit.dynamics.kernels.assembly import FreePattern  # noqa: E402
from femkit.dynamics.system import elastic_system  # noqa: E402
from femkit.dynamics.topology import cloth_grid  # noqa: E402
from femkit.mesh.structured import structured_box  # noqa: E402
from femkit.solids import ElasticBody, material  # noqa: E402
from femkit.solids.boundary import tagged_nodes  # noqa: E402


def unique_keys(system) -> tuple[np.ndarray, np.ndarray]:
    """The peer: CSR ``indptr``, ``indices`` of the free-dof pattern by one ``np.unique`` over
    every dof-level entry (and the inverse map it needs for the slots, computed and dropped)."""
    d, ndof = system.dim, system.ndof
    p, q = np.repeat(np.arange(d), d), np.tile(np.arange(d), d)
    i, j, nodes = system.springs[:, 0], system.springs[:, 1], np.arange(system.n)
    rows = [(a[:, None] * d + p).ravel() for a in (i, j, i, j, nodes)]
    cols = [(b[:, None] * d + q).ravel() for b in (i, j, j, i, nodes)]
    for f in system.forces:
        st = f.structure()
        if st is not None:
            rows.append(np.repeat(np.arange(ndof), np.diff(st[0])))
            cols.append(np.asarray(st[1], dtype=np.int64))
    free = system.free_dofs
    nf = len(free)
    new = np.full(ndof, -1)
    new[free] = np.arange(nf)
    r, c = new[np.concatenate(rows)], new[np.concatenate(cols)]
    ok = (r >= 0) & (c >= 0)
    keys, _ = np.unique(r[ok] * nf + c[ok], return_inverse=True)
    return np.concatenate([[0], np.cumsum(np.bincount(keys // nf, minlength=nf))]), keys % nf


def scenes():
    cloth = cloth_grid(81, 81, 1.0, 1.0, k_structural=400.0, k_shear=100.0, k_bending=10.0,
                       total_mass=0.5, pinned="top_corners", plane="xy")
    mesh = structured_box(24, 12, 12, (4.0, 1.0, 1.0))
    body = ElasticBody.from_mesh(mesh, material("stable_neo_hookean", E=1e3, nu=0.3, density=1.0))
    body.pattern    # the body's own pattern is built with the body, not with the free pattern
    return {"cloth 81x81": cloth, "elastic box 24x12x12": elastic_system(body, pinned=tagged_nodes(mesh, "xmin"))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    print(f"{'scene':24s} {'dofs':>7s} {'nnz':>9s} {'FreePattern':>12s} {'np.unique':>10s} {'ratio':>6s}")
    for name, system in scenes().items():
        pat = FreePattern(system)
        indptr, indices = unique_keys(system)
        assert np.array_equal(pat.indptr, indptr) and np.array_equal(pat.indices, indices)
        times = {"ours": [], "peer": []}
        for _ in range(args.repeat):
            for key, build in (("ours", FreePattern), ("peer", unique_keys)):
                t = time.process_time()
                build(system)
                times[key].append(time.process_time() - t)
        ours, peer = statistics.median(times["ours"]), statistics.median(times["peer"])
        print(f"{name:24s} {pat.shape[0]:7d} {pat.nnz:9d} {1e3 * ours:9.1f} ms {1e3 * peer:7.1f} ms "
              f"{ours / peer:6.2f}")


if __name__ == "__main__":
    main()
