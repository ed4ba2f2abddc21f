"""Measure the cost of the Poisson pipeline stage by stage (what the cost model is calibrated on).

Used by ``calibrate_cost.py`` and ``bench_cost_model.py`` (run as scripts from this folder)
and by the model-against-measurement tests; it runs femkit's library, which the cost model
itself (:mod:`femkit.cost`, pure functions of numbers) never does.

:func:`measure_poisson` runs mesh generation, refinement, assembly, Dirichlet elimination,
the solve, error norms and output writing with the library functions the case runner uses, and
records per stage the wall time and the peak resident memory above the resident memory at
the start (``VmHWM`` reset before each stage, :mod:`femkit.cost.memory`). Run it in a fresh
process (:func:`measure_poisson_subprocess`) so that memory freed by an earlier run does not
hide the cost of this one.

The model (:func:`femkit.cost.plan_poisson`) and this probe use the same stage names.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from femkit.cost.memory import current_rss, peak_rss, reset_peak_rss

__all__ = ["measure_poisson", "measure_poisson_subprocess", "preload", "child_env", "domain",
           "measure_case", "measure_case_subprocess", "CUBE_CASE"]


def domain(geometry: str, params: dict | None = None) -> dict:
    """The numbers :func:`femkit.cost.plan_poisson` takes for a registered geometry:
    ``{area, line_length, name, params}`` (the measure declared with the geometry)."""
    from femkit.case.cost import geometry_domain

    _, area, length = geometry_domain(geometry, params)
    return dict(area=area, line_length=length, name=geometry, params=params or None)


def preload() -> None:
    """Import what every run imports, so the baseline memory is measured after the imports.

    gmsh, numba, pyamg and matplotlib are left out: the cost model counts their import in the
    stage that first needs them (``bytes.gmsh_import`` ...).
    """
    import meshio  # noqa: F401
    import scipy.sparse.linalg  # noqa: F401

    import femkit.fem  # noqa: F401
    import femkit.mesh  # noqa: F401
    import femkit.solvers  # noqa: F401


def measure_poisson(geometry: str = "unit_square", h: float = 0.05, refine: int = 0, *,
                    params: dict | None = None, method: str = "pcg",
                    preconditioner: str = "amg_sa", rtol: float = 1e-8,
                    outputs: tuple[str, ...] = ("vtu",), errors: bool = True) -> dict:
    """Run the pipeline once in this process; per stage ``seconds`` and ``peak_bytes``.

    Returns
    -------
    dict
        ``stages`` ``{name: {"seconds", "peak_bytes"}}`` (peak above the RSS at the start),
        ``baseline_bytes`` (RSS at the start, after :func:`preload`), ``peak_bytes`` (largest
        stage peak), ``n_triangles``, ``n_points``, ``dofs``, ``nnz``, ``iterations``,
        ``output_bytes``, ``setup_seconds`` and ``solve_seconds`` (from the solver).
    """
    preload()
    from femkit.fem import apply_dirichlet, assemble_load, assemble_stiffness, error_norms
    from femkit.mesh import boundary_nodes, generate, quality, validate, write_mesh
    from femkit.mesh import refine as refine_mesh
    from femkit.solvers import solve

    base = current_rss() or 0
    stages: dict[str, dict] = {}

    def stage(name, fn):
        reset_peak_rss()
        t0 = time.perf_counter()
        out = fn()
        stages[name] = {"seconds": time.perf_counter() - t0,
                        "peak_bytes": max((peak_rss() or 0) - base, 0)}
        return out

    def exact(x, y):
        return np.sin(np.pi * x) * np.sin(np.pi * y)

    def source(x, y):
        return 2 * np.pi ** 2 * exact(x, y)

    mesh = stage("mesh", lambda: validate(generate(geometry, h, **(params or {}))))
    n_generated = mesh.n_triangles
    if refine:
        mesh = stage("refine", lambda: refine_mesh(mesh, refine))
    stage("quality", lambda: quality(mesh))
    K, F = stage("assembly", lambda: (assemble_stiffness(mesh, 1.0), assemble_load(mesh, source)))
    system = stage("boundary", lambda: apply_dirichlet(K, F, boundary_nodes(mesh, None), 0.0))
    pc = preconditioner if method == "pcg" else None
    res = stage("solve", lambda: solve(system.A, system.b, method=method, preconditioner=pc,
                                       rtol=rtol, maxiter=20000))
    u = system.expand(res.x)
    if errors:
        stage("errors", lambda: error_norms(mesh, u, exact))
    from femkit.fem import PoissonProblem
    from femkit.fem.estimators import estimate

    problem = PoissonProblem(mesh, np.ones(mesh.n_triangles), source)  # u = 0 on the boundary
    stage("estimate", lambda: estimate(problem, u, "residual"))
    out_bytes = 0
    with tempfile.TemporaryDirectory() as tmp:
        def write():
            nonlocal out_bytes
            data = {"u": u}
            for kind in outputs:
                if kind in ("vtu", "xdmf"):
                    write_mesh(os.path.join(tmp, f"solution.{kind}"), mesh, point_data=data,
                               cell_data={"tag": mesh.cell_tags, "kappa": np.ones(mesh.n_triangles)})
                elif kind == "png":
                    _png(os.path.join(tmp, "solution.png"), mesh, u)
            out_bytes = sum(os.path.getsize(os.path.join(tmp, f)) for f in os.listdir(tmp))
        if outputs:
            stage("output", write)
    return {
        "geometry": geometry, "h": h, "refine": refine, "params": params or {},
        "method": method, "preconditioner": pc or "none", "outputs": list(outputs),
        "n_generated": n_generated, "n_triangles": mesh.n_triangles, "n_points": mesh.n_points,
        "dofs": int(system.A.shape[0]), "nnz": int(system.A.nnz), "nnz_K": int(K.nnz),
        "iterations": int(res.iterations), "converged": bool(res.converged),
        "setup_seconds": float(res.setup_time), "solve_seconds": float(res.solve_time),
        "fill": (res.info or {}).get("nnz_L", 0) + (res.info or {}).get("nnz_U", 0),
        "output_bytes": out_bytes, "baseline_bytes": base, "stages": stages,
        "peak_bytes": max(s["peak_bytes"] for s in stages.values()),
    }


def _png(path: str, mesh, u) -> None:
    """A filled-contour PNG like the case runner's (same size, dpi and shading)."""
    from matplotlib.figure import Figure
    from matplotlib.tri import Triangulation

    fig = Figure(figsize=(6, 5), dpi=120)
    ax = fig.add_subplot()
    art = ax.tripcolor(Triangulation(mesh.points[:, 0], mesh.points[:, 1], mesh.triangles), u,
                       shading="gouraud", cmap="viridis")
    fig.colorbar(art, ax=ax, label="u")
    fig.savefig(path, format="png")


def child_env() -> dict:
    """Environment of a measuring child process: BLAS on one thread, and this femkit first on
    the path (the child imports the same femkit as the parent, installed or not)."""
    here = os.path.abspath(os.path.dirname(__file__))  # <root>/benchmarks
    root = os.path.dirname(here)
    path = os.pathsep.join(p for p in (root, here, os.environ.get("PYTHONPATH", "")) if p)
    return dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
                MPLBACKEND="Agg", PYTHONPATH=path)


def measure_poisson_subprocess(timeout: float = 600.0, **kwargs) -> dict:
    """:func:`measure_poisson` in a fresh Python process (BLAS pinned to one thread)."""
    env = child_env()
    code = ("import json, sys; from cost_probe import measure_poisson; "
            "print(json.dumps(measure_poisson(**json.loads(sys.argv[1]))))")
    out = subprocess.run([sys.executable, "-c", code, json.dumps(kwargs)], capture_output=True,
                         text=True, env=env, timeout=timeout, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"probe failed ({out.returncode}): {out.stderr.strip()[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


#: The tetrahedral case the 3D memory model is calibrated on (as ``bench_poisson3d.py --memory``):
#: the Kuhn cube of side ``h`` refined ``refine`` times, fmg, errors and the estimate, no files.
CUBE_CASE = {
    "problem": "poisson", "name": "probe3d",
    "mesh": {"geometry": "kuhn_cube", "h": 1 / 3, "refine": 3},
    "source": "-(1 + 0.25 + 0.09) * exp(x + 0.5*y - 0.3*z)",
    "boundary": {"dirichlet": [{"tags": ["boundary"], "value": "exp(x + 0.5*y - 0.3*z)"}]},
    "exact": {"u": "exp(x + 0.5*y - 0.3*z)",
              "grad": ["exp(x + 0.5*y - 0.3*z)", "0.5*exp(x + 0.5*y - 0.3*z)",
                       "-0.3*exp(x + 0.5*y - 0.3*z)"]},
    "solver": {"method": "fmg"},
    "output": {"vtu": False, "plot": False},
}


def measure_case(case: dict) -> dict:
    """Run a case file's dict through ``femkit solve``'s pipeline in this process (kernels
    compiled first, outside the stages); per stage of its :class:`~femkit.timing.StageTimer`
    the wall time and the peak resident memory above the resident memory at the start (VmHWM
    reset when a stage starts, read when it ends and when a stage inside it starts; a stage
    entered twice keeps its largest).

    Returns ``{"stages": {name: {"seconds", "peak_bytes"}}, "baseline_bytes", "peak_bytes",
    "n_cells", "n_points"}``.
    """
    preload()
    import femkit.timing as timing
    from femkit.case.load import case_from_dict
    from femkit.case.poisson.warmup import warm_up

    warm_up()
    import contextlib

    base = current_rss() or 0
    stages: dict[str, dict] = {}
    sizes = {}

    open_peaks: list[int] = []  # running peak of each stage entered and not left (nested stages)

    def fold() -> int:
        now = max((peak_rss() or 0) - base, 0)
        for k in range(len(open_peaks)):
            open_peaks[k] = max(open_peaks[k], now)
        return now

    @contextlib.contextmanager
    def probe(self, name):
        fold()                      # an enclosing stage keeps its peak so far: reset below
        reset_peak_rss()
        open_peaks.append(0)
        t0 = time.perf_counter()
        try:
            yield
        finally:
            dt = time.perf_counter() - t0
            fold()
            peak = open_peaks.pop()
            self.times[name] = self.times.get(name, 0.0) + dt
            got = stages.setdefault(name, {"seconds": 0.0, "peak_bytes": 0})
            got["seconds"] += dt
            got["peak_bytes"] = max(got["peak_bytes"], peak)

    timing.StageTimer.__call__ = probe
    result = case_from_dict(case).run(write=False, quiet=True)
    mesh = getattr(result, "mesh", None)
    if mesh is not None:
        sizes = {"n_cells": int(mesh.n_cells), "n_points": int(mesh.n_points)}
    return {"stages": stages, "baseline_bytes": base,
            "peak_bytes": max(s["peak_bytes"] for s in stages.values()), **sizes}


def measure_case_subprocess(case: dict, timeout: float = 3600.0) -> dict:
    """:func:`measure_case` in a fresh Python process (BLAS pinned to one thread)."""
    code = ("import json, sys; from cost_probe import measure_case; "
            "print(json.dumps(measure_case(json.loads(sys.argv[1]))))")
    out = subprocess.run([sys.executable, "-c", code, json.dumps(case)], capture_output=True,
                         text=True, env=child_env(), timeout=timeout, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"probe failed ({out.returncode}): {out.stderr.strip()[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])
