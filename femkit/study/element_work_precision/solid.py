"""The solid runs of an ``element_work_precision`` study (a ``problem: solid`` base case).

Each element on the base case's mesh at ``levels.h0`` and its uniform refinements (tags kept),
solved statically as the case says (:func:`femkit.solids.solve_static` with its load steps,
Newton settings and linear solver). The error of a run is relative: ``|u_c(point) - value| /
|value|`` for the node at ``reference.point`` and the displacement component
``reference.component`` (Cook's membrane: the corner (48, 60), vertical, against the converged
value of scripts/cook_reference.py). The run time is building the body, its loads and boundary
conditions on the level's mesh plus the static solve (the minimum over ``repeats``); meshing is
not in it, as for the Poisson runs.
"""

from __future__ import annotations

import numpy as np

from ...errors import CaseFileError
from ...interrupt import checkpoint
from ...progress import Progress
from ..timing import time_call

__all__ = ["solid_records"]


def _solve(case, mesh) -> tuple:
    """Build the problem on ``mesh`` and solve it: ``(problem, displacements (n, d))``."""
    from ...case.solid.run import build_problem
    from ...solids import solve_static

    problem = build_problem(case, mesh)
    st, body = case.spec.static, problem.body
    res = solve_static(body, problem.dirichlet(1.0), problem.traction + problem.weight,
                       load_steps=st.load_steps, project=st.project, rtol=st.rtol,
                       max_iterations=st.max_iterations, linear_solver=case.spec.solver)
    return problem, np.asarray(res.u).reshape(body.n, -1)


def _node(points: np.ndarray, point) -> int:
    """The node at ``point`` (a vertex of the geometry: a node on every level)."""
    hit = np.flatnonzero(np.all(np.isclose(points, np.asarray(point, float), rtol=0.0,
                                           atol=1e-9 * np.ptp(points, axis=0).max()), axis=1))
    if not len(hit):
        raise CaseFileError(f"reference.point {list(point)} is not a node of the mesh; give a "
                            "vertex of the geometry (a node on every refinement)")
    return int(hit[0])


def solid_records(study, *, quiet: bool = False) -> list[dict]:
    """One record per (element, level): dofs, ``t``, the displacement and its relative error
    (``corner``)."""
    from ...case.solid.run import build_mesh
    from ...mesh import refine
    from ..spec import load_base_case

    d, ref = study.spec, study.spec.reference
    cases = {e: load_base_case(study, mesh={"h": d.h0}, element=e)[1] for e in d.elements}
    meshes = [build_mesh(cases[d.elements[0]].spec)]
    comp, value = int(ref["component"]), float(ref["value"])
    if comp >= meshes[0].dim:
        raise CaseFileError(f"reference.component: {comp} for a {meshes[0].dim}D mesh; valid: "
                            + ", ".join(f"{i} ({'xyz'[i]})" for i in range(meshes[0].dim)))
    _node(meshes[0].points, ref["point"])      # refused before any solve
    jobs = [(e, k) for e, count in zip(d.elements, d.counts) for k in range(count)]
    if d.warmup:                                # untimed: compiled kernels, factorisation set-up
        for e in d.elements:
            _solve(cases[e], meshes[0])
    bar = Progress(len(jobs), study.name, unit="run", quiet=quiet)
    records = []
    for element, level in jobs:
        checkpoint(f"before {element} level {level}")
        while len(meshes) <= level:
            meshes.append(refine(meshes[-1], 1))
        t = time_call(lambda: _solve(cases[element], meshes[level]), repeats=d.repeats, warmup=0)
        problem, u = t.value
        disp = float(u[_node(problem.body.rest_positions, ref["point"]), comp])
        records.append({"element": element, "refinement": "uniform", "level": level,
                        "cells": meshes[level].n_cells, "h": float(d.h0) / 2 ** level,
                        "dofs": int(problem.body.ndof), "nnz": None, "iterations": None,
                        "converged": True, "t": t.min, "t_median": t.median,
                        "displacement": disp, "corner": abs(disp - value) / abs(value)})
        bar.update()
    bar.close()
    return records
