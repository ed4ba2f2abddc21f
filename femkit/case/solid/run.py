"""Run a ``problem: solid`` case: mesh, materials per region, boundaries, then a quasi-static
solve (load steps) or a time integration, then the outputs.

:func:`prepare_solid` checks everything it can at load time -- material constants and names,
boundary and region tags of a registered geometry, the integrator or ``static`` choice, the
linear solver -- and builds the frozen :class:`~femkit.case.solid.spec.SolidSpec`;
:func:`run_solid` checks the rest (tags of a mesh file, inverted input elements) before anything
is written. Every such failure is a one-line :class:`~femkit.errors.InputError` (exit 2).

A Newton failure (:class:`~femkit.errors.EquilibriumError`: of the static solve, or of an
implicit time step, :class:`~femkit.dynamics.integrators.base.NewtonStepError`), another failed
step (a linear solve) and an unstable time integration do not escape :func:`run_solid`: the
frames computed before (load steps or time steps) are written, ``result.json`` says
``converged: false`` with the failure and, for Newton, the residual history; ``femkit solve``
exits 1.

Time integration holds every fixed or roller component (per component: rollers slide) at its
prescribed displacement from ``t = 0`` (:class:`~femkit.dynamics.system.MassSpringSystem`'s
``(n, d)`` pin mask).

Static runs are one :func:`femkit.solids.solve_static` with ``load_steps=K``: load step ``k``
applies ``k/K`` of the loads and prescribed displacements from the previous equilibrium (the
prescribed increment spread into the body by a linear solve, the step cut when that start still
inverts elements); each equilibrium is kept as a frame (its ``on_step``), and a stop request is
seen between Newton iterations (its ``stop``).

SIGINT / SIGTERM (``case.options.stop``): see :func:`run_solid`.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ...errors import (CaseFileError, DegenerateMeshError, EquilibriumError, InputError,
                       InstabilityError, SolverError, with_prefix)
from ...io.atomic import EARLIER_RUN, check_output_dir
from ...kinds import KINDS
from ...timing import StageTimer
from ..contact import (MOTION, ContactRecorder, build_contact, check_contact_integrator,
                       resolve_obstacle_files)
from ..frozen import freeze
from ..name_checks import check_geometry_spec, resolve_file
from ..result import RunResult
from ..specs import IntegratorSpec, limits_spec, solver_spec
from ..timeline import time_value
from .schema import COMPONENTS
from .spec import Boundary, SolidOutput, SolidSpec, StaticSpec

__all__ = ["prepare_solid", "run_solid", "build_mesh", "folded_cells", "build_problem", "SolidProblem",
           "SolidResult", "frame_energies"]


# ----------------------------------------------------------------------------- prepare

def _materials(d) -> dict:
    from ...solids.materials import material_from_spec

    out = {}
    for where, spec in [("material", d["material"])] + [
            (f"regions.{name}", s) for name, s in d["regions"].items()]:
        try:
            out[None if where == "material" else where.split(".", 1)[1]] = material_from_spec(spec)
        except InputError as exc:
            raise with_prefix(exc, where) from None
    return out


def _boundaries(d) -> tuple:
    out = []
    for i, b in enumerate(d["boundaries"]):
        where = f"boundaries[{i}]"
        if b["type"] == "traction":
            out.append(Boundary(b["tag"], "traction", traction=tuple(b["traction"])))
            continue
        comps = tuple(COMPONENTS.index(c) for c in b.get("fix", ()))  # () = every component
        out.append(Boundary(b["tag"], b["type"], comps, tuple(b.get("displacement", ()))))
    return tuple(out)


def _check_geometry_tags(d, boundaries) -> int | None:
    """Boundary tags and region names of a registered geometry, checked now; its dimension."""
    if "geometry" not in d["mesh"]:
        return None
    from ...mesh.geometries import GEOMETRIES

    entry = GEOMETRIES.get(d["mesh"]["geometry"])
    for i, b in enumerate(boundaries):
        if isinstance(b.tag, str) and b.tag not in entry.boundary_tags:
            raise CaseFileError(f"boundaries[{i}].tag: unknown boundary tag {b.tag!r} of geometry "
                                f"{entry.name!r}; valid tags: {', '.join(entry.boundary_tags)}")
    for name in d["regions"]:
        if name not in entry.cell_tags:
            raise CaseFileError(f"regions: unknown region {name!r} of geometry {entry.name!r}; "
                                f"valid regions: {', '.join(entry.cell_tags) or '(none)'}")
    return entry.dim


def _bodies(d, base, mesh: dict, material, dynamic: bool) -> tuple | None:
    """``bodies:`` checked: each body's mesh (default the file's ``mesh``), material (default
    ``material``), offset and velocity; only for a time integration without boundaries or
    regions (their tags would be ambiguous among the bodies)."""
    if not d.get("bodies"):
        return None
    from ...solids.materials import material_from_spec

    if not dynamic or d["boundaries"] or d["regions"]:
        raise CaseFileError("bodies: several bodies take a time integration with neither "
                            "'boundaries' nor 'regions' (free bodies in contact)")
    out = []
    for i, b in enumerate(d["bodies"]):
        where = f"bodies[{i}]"
        m = dict(b.get("mesh") or mesh)
        if "mesh" in b and "file" in m:
            resolve_file(m, f"{where}.mesh", base)
        elif "mesh" in b:
            check_geometry_spec(m, f"{where}.mesh")
        try:
            mat = material_from_spec(b["material"]) if "material" in b else material
        except InputError as exc:
            raise with_prefix(exc, f"{where}.material") from None
        vel = b.get("velocity", d.get("velocity"))
        out.append(freeze({"mesh": m, "material": mat, "offset": tuple(b["offset"]),
                           "velocity": None if vel is None else tuple(vel)}))
    return tuple(out)


def prepare_solid(case) -> None:
    """Check a validated solid case and build its :class:`SolidSpec` (``case.spec``).

    Raises
    ------
    MaterialError
        ``E <= 0``, ``nu`` outside ``(-1, 1/2)``, ``density <= 0``, missing constants.
    UnknownNameError
        Unknown material, geometry, integrator, solver (valid names listed).
    CaseFileError
        Unknown boundary tag or region of a geometry, both or neither of ``static`` and
        ``integrator``, a vector of the wrong dimension.
    """
    d = case.data
    if d.get("name"):
        case.name = d["name"]
    mesh = dict(d["mesh"])
    if "file" in mesh:
        resolve_file(mesh, "mesh", case.base_dir)
    else:
        check_geometry_spec(mesh, "mesh")
    materials = _materials(d)
    static = d["static"]
    dynamic = "integrator" in d
    if bool(static) == dynamic:
        raise CaseFileError("give either 'static: true' (equilibrium) or an 'integrator' with "
                            "'dt' and 't_end' (time integration)" if not dynamic else
                            "'static' and 'integrator' exclude each other: give one")
    boundaries = _boundaries(d)
    dim = _check_geometry_tags(d, boundaries)
    element = d["element"]
    for key in ("gravity", "velocity"):
        if dim is not None and key in d and len(d[key]) != dim:
            raise CaseFileError(f"{key}: needs {dim} components for a {dim}D mesh, got {len(d[key])}")
    for i, b in enumerate(boundaries):
        for what in ("displacement", "traction"):
            v = getattr(b, what)
            if dim is not None and v and len(v) != dim:
                raise CaseFileError(f"boundaries[{i}].{what}: needs {dim} components, got {len(v)}")
    if not dynamic and all(b.kind == "traction" for b in boundaries):
        raise CaseFileError("boundaries: no fixed or roller condition: a static body with no "
                            "support is singular (rigid-body motions, no unique equilibrium); "
                            "hold a tag, or integrate in time (a body in free flight)")
    solver = solver_spec(d["linear_solver"], "linear_solver",
                                       default_method=KINDS.get(case.problem, "problem").default_solver)
    case.options = dataclasses.replace(case.options, limits=limits_spec(d.get("limits")))
    out = d["output"]
    if dynamic:
        for key in ("dt", "t_end"):
            if key not in d:
                raise CaseFileError(f"{key}: a time integration needs 'dt' and 't_end'")
        integ = IntegratorSpec.from_mapping(d["integrator"], "integrator")
        _check_element(integ, element)
        dt, t_end = time_value(case, "dt"), time_value(case, "t_end")
        steps = int(round(t_end / dt))
        if steps < 1:
            raise CaseFileError(f"t_end: {t_end:g} is shorter than one step dt = {dt:g}")
        static_spec = None
        every = int(out["every"]) if "every" in out else max(1, math.ceil(steps / int(out["frames"])))
    else:
        for key in ("dt", "t_end", "velocity"):
            if key in d:
                raise CaseFileError(f"{key}: only for a time integration (this case is static)")
        integ, dt, t_end = None, None, None
        static_spec = StaticSpec(**({} if static is True else dict(static)))
        steps, every = static_spec.load_steps, int(out.get("every", 1))
    bodies = _bodies(d, case.base_dir, mesh, materials[None], dynamic)
    contact = dict(d["contact"]) if d.get("contact") is not None else None
    if contact is not None:
        if dynamic:
            check_contact_integrator(integ.method)
        if not dynamic and contact.get("friction"):
            raise CaseFileError("contact.friction: friction needs a time integration (it lives "
                                "on the step's velocity); a static run is frictionless")
        if not dynamic and any(k in o for o in contact.get("obstacles") or [] for k in MOTION):
            raise CaseFileError(f"contact.obstacles: a moving obstacle ({', '.join(MOTION)}) "
                                "needs a time integration; a static run keeps obstacles where "
                                "they are")
        contact["obstacles"] = [dict(o) for o in contact.get("obstacles") or []]
        resolve_obstacle_files(contact, case.base_dir)
    directory = str((case.base_dir / out.get("dir", os.path.join("runs", case.name))).resolve())
    out["dir"] = directory
    case.spec = SolidSpec(
        mesh=freeze(mesh), materials=freeze(materials), boundaries=boundaries,
        gravity=tuple(d["gravity"]) if "gravity" in d else None, static=static_spec,
        integrator=integ, solver=solver, dt=dt, t_end=t_end, steps=steps,
        velocity=tuple(d["velocity"]) if "velocity" in d else None,
        output=SolidOutput(directory, every, bool(out["vtu"]), bool(out["png"]), bool(out["gif"])),
        element=element, contact=None if contact is None else freeze(contact), bodies=bodies)


def _check_element(integ: IntegratorSpec, element: str) -> None:
    """An integrator that declares the elements it integrates (``Integrator.elements``, e.g.
    projective dynamics' P1 local step) refuses the others in one line."""
    allowed = getattr(integ.build(), "elements", None)
    if allowed is not None and element not in allowed:
        raise CaseFileError(f"element: {element} is not supported by the integrator "
                            f"{integ.method!r} (it integrates {', '.join(allowed)} only); use "
                            f"element: {allowed[0]} or another integrator")


# ----------------------------------------------------------------------------- build

def folded_cells(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Cells folded over a neighbour: two cells sharing a facet whose opposite vertices lie on
    the same side of it overlap, so one is inverted whatever its vertex order (a reader that
    reorients cells hides the order, not the overlap). Returns the cells taking part in the
    most such folds (the inverted ones when they are isolated), sorted; empty when none."""
    m, nv = cells.shape
    d = nv - 1
    facets = np.concatenate([np.delete(cells, k, axis=1) for k in range(nv)])
    opposite = np.concatenate([cells[:, k] for k in range(nv)])
    owner = np.tile(np.arange(m), nv)
    key = np.sort(facets, axis=1)
    order = np.lexsort(key.T[::-1])
    key, facets, opposite, owner = key[order], facets[order], opposite[order], owner[order]
    pair = np.flatnonzero(np.all(key[1:] == key[:-1], axis=1))
    if not len(pair):
        return np.zeros(0, np.int64)
    base = key[pair]                                   # the same vertex order for both sides
    P = points[base]                                    # (k, d, d)
    edges = P[:, 1:] - P[:, :1]                         # (k, d-1, d)

    def side(p):
        return np.sign(np.linalg.det(np.concatenate([edges, (p - P[:, 0])[:, None]], axis=1)))

    same = side(points[opposite[pair]]) * side(points[opposite[pair + 1]]) > 0
    if not same.any():
        return np.zeros(0, np.int64)
    count = np.bincount(np.concatenate([owner[pair[same]], owner[pair[same] + 1]]), minlength=m)
    return np.flatnonzero(count == count.max())


def _reoriented(mesh) -> tuple:
    """``mesh`` with its cells listed in the other vertex order turned round, and how many: the
    file's vertex order is bookkeeping, not geometry. Cells that are geometrically inverted
    (folded over a neighbour) are still refused after this."""
    from ...mesh.validate import orient_ccw

    return orient_ccw(mesh), int((mesh.signed_volumes() < 0).sum())


def build_mesh(spec: SolidSpec):
    """The validated rest mesh, generated or read (a file's cells listed in the opposite vertex
    order re-oriented, saying how many); refused with
    :class:`~femkit.errors.DegenerateMeshError` naming the elements when some are inverted
    (cells folded over a neighbour: :func:`folded_cells`)."""
    if spec.bodies is not None:
        return _merged_bodies(spec.bodies)
    return _one_mesh(spec.mesh)


def _merged_bodies(bodies):
    """One mesh of every body's mesh moved by its offset, cells tagged by body (1, 2, ...)."""
    from ...mesh import Mesh

    points, cells, tags, off = [], [], [], 0
    for k, b in enumerate(bodies):
        m = _one_mesh(b["mesh"])
        offset = np.asarray(b["offset"], float)
        if len(offset) != m.dim:
            raise CaseFileError(f"bodies[{k}].offset: needs {m.dim} components, got {len(offset)}")
        points.append(m.points + offset)
        cells.append(m.cells + off)
        tags.append(np.full(m.n_cells, k + 1))
        off += m.n_points
    return Mesh(np.concatenate(points), np.concatenate(cells), cell_tags=np.concatenate(tags))


def _one_mesh(m):
    """The validated mesh of one ``mesh:`` mapping (see :func:`build_mesh`)."""
    from ...mesh import generate, read_mesh, validate

    where = f"mesh.file {m['file']}" if "file" in m else f"mesh.geometry {m['geometry']}"
    try:
        flipped = 0
        if "file" in m:
            mesh, flipped = _reoriented(read_mesh(m["file"], orient=False))
        else:
            mesh = generate(m["geometry"], m["h"], **dict(m.get("params") or {}))
        neg = mesh.signed_volumes() < 0
        bad = np.flatnonzero(neg if neg.sum() <= (~neg).sum() else ~neg) if neg.any() else \
            folded_cells(mesh.points, mesh.cells)
        if len(bad):
            raise DegenerateMeshError(
                f"{len(bad)} inverted {mesh.cell_name}(s) in the input mesh (overlapping their "
                f"neighbours): element ids {', '.join(map(str, bad[:10]))}"
                f"{' ...' if len(bad) > 10 else ''}", element_ids=bad)
        mesh = validate(mesh)
        if flipped:  # said once the mesh is accepted: a refusal stays one line
            print(f"femkit: note: {where}: {flipped:,} of {mesh.n_cells:,} {mesh.cell_name}(s) "
                  "listed with the opposite vertex order; re-oriented", file=sys.stderr)
        return mesh
    except InputError as exc:
        raise with_prefix(exc, where) from None


@dataclass
class SolidProblem:
    """The built problem: mesh, body, Dirichlet data, external nodal loads (traction and
    gravity, ``(n, d)`` each) and the gravity vector."""

    mesh: Any
    body: Any
    fixes: list
    traction: np.ndarray
    weight: np.ndarray
    gravity: np.ndarray

    def dirichlet(self, scale: float = 1.0):
        """The :class:`~femkit.solids.Dirichlet` data with every prescribed displacement times
        ``scale`` (a load step)."""
        from ...solids import Dirichlet

        bc = Dirichlet(self.body.n, self.body.dim)
        for nodes, comps, disp in self.fixes:
            bc.fix(nodes, components=comps, displacement=scale * disp)
        return bc


def build_problem(case, mesh=None) -> SolidProblem:
    """Mesh, body (a material per region), boundary conditions and loads of a prepared case;
    ``mesh`` (optional) replaces the case's own (a refinement of it, with its tags: a study's
    levels)."""
    from ...solids import ElasticBody, body_forces, traction_forces
    from ...solids.boundary import tagged_facets

    spec = case.spec
    mesh = build_mesh(spec) if mesh is None else mesh
    d = mesh.dim
    for key, v in (("gravity", spec.gravity), ("velocity", spec.velocity)):
        if v is not None and len(v) != d:
            raise CaseFileError(f"{key}: needs {d} components for a {d}D mesh, got {len(v)}")
    mats = dict(spec.materials)
    default = mats.pop(None)
    regions = {}
    for name, mat in mats.items():
        try:
            regions[mesh.tag(name)] = mat
        except InputError as exc:
            raise with_prefix(exc, f"regions.{name}") from None
    if spec.bodies is not None:   # cells tagged by body
        material = {k + 1: b["material"] for k, b in enumerate(spec.bodies)}
    elif regions:
        tags = np.unique(mesh.cell_tags)
        regions.update({int(t): default for t in tags if int(t) not in regions})
        material = regions
    else:
        material = default
    body = ElasticBody(mesh.points, mesh.cells, material, cell_tags=mesh.cell_tags,
                       element=spec.element, mesh=mesh)
    traction = np.zeros((body.n, d))
    fixes = []
    for i, b in enumerate(spec.boundaries):
        where = f"boundaries[{i}]"
        try:
            facets = tagged_facets(mesh, b.tag)
            if spec.element != "P1":          # the facets' edge midpoints are nodes too
                from ...solids.quadratic import facet_nodes

                facets = facet_nodes(mesh, facets, spec.element)
            for what in ("displacement", "traction"):
                v = getattr(b, what)
                if v and len(v) != d:
                    raise CaseFileError(f"{what}: needs {d} components, got {len(v)}")
            if b.kind == "traction":
                traction += traction_forces(body.rest_positions, facets, b.traction)
            else:
                nodes = np.unique(facets)
                disp = np.zeros(d)
                disp[:len(b.displacement)] = b.displacement
                if any(c >= d for c in b.components):
                    raise CaseFileError(f"fix: a {d}D mesh has components "
                                        f"{', '.join(COMPONENTS[:d])} only")
                fixes.append((nodes, list(b.components) or None, disp))
        except InputError as exc:
            raise with_prefix(exc, where) from None
    g = np.zeros(d) if spec.gravity is None else np.asarray(spec.gravity, dtype=float)
    weight = body_forces(body, body.density()[:, None] * g[None, :])
    problem = SolidProblem(mesh, body, fixes, traction, weight, g)
    problem.dirichlet(1.0)  # a dof prescribed twice with different values: InputError now
    return problem


def frame_energies(problem: SolidProblem, x: np.ndarray, v: np.ndarray | None = None,
                   load_factor: float = 1.0) -> dict:
    """Energies of one frame: ``kinetic`` (lumped masses), ``elastic``, ``gravity``
    (``-sum m_i g . u_i``, zero at rest), ``load`` (``-f_traction . u``) and ``total``; the
    external loads times ``load_factor`` (a static load step applies that part of them)."""
    body = problem.body
    u = x - body.rest_positions
    out = {"kinetic": 0.0 if v is None else
           float(0.5 * np.einsum("n,nd,nd->", body.lumped_masses(), v, v)),
           "elastic": body.energy(x),
           "gravity": 0.0 - load_factor * float(np.einsum("nd,nd->", problem.weight, u)),
           "load": 0.0 - load_factor * float(np.einsum("nd,nd->", problem.traction, u))}
    out["total"] = sum(out.values())
    return out


# ----------------------------------------------------------------------------- result

@dataclass
class SolidResult(RunResult):
    """What a solid run produced: frames (times or load factors, positions, velocities), their
    energies and fields, and the facts of ``result.json`` (the solid kind's
    :class:`~femkit.case.result.RunResult`; ``verdict`` names its failure: ``newton_failed``,
    ``solver_failed``, ``unstable``)."""

    case: Any
    problem: SolidProblem
    times: np.ndarray
    x: list
    v: list
    energies: list
    records: list = field(default_factory=list)
    failure: str | None = None
    residual_history: list | None = None
    verdict: str = "converged"
    wall_time: float = 0.0
    timings: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    output_dir: Any = None
    files: list = field(default_factory=list)
    contact: Any = None            # ContactRecorder of a run with barrier contact
    contact_forces: list = field(default_factory=list)   # (n, 3) per frame
    steps: int = 0                   # time or load steps done
    stopped: str | None = None       # the signal that stopped the solve ("SIGINT" ...), if one did
    output_stop: str | None = None   # the signal that stopped the output, if one did
    frames_written: int | None = None  # frames written before that stop (None: all)
    warnings: list = field(default_factory=list)
    _fields: dict = field(default_factory=dict, repr=False)

    @property
    def converged(self) -> bool:
        """False when the solve failed or was stopped before its end."""
        return self.failure is None and self.stopped is None

    @property
    def interrupted(self) -> str | None:
        """The signal that stopped the solve or the writing of its outputs, else None."""
        return self.stopped or self.output_stop

    def fields(self, k: int) -> dict:
        """Per-element fields of frame ``k`` (:meth:`femkit.solids.ElasticBody.element_fields`)."""
        k = k % len(self.x)
        if k not in self._fields:
            self._fields[k] = self.problem.body.element_fields(self.x[k])
        return self._fields[k]

    def tip(self, k: int = -1) -> np.ndarray:
        """The largest displacement of frame ``k`` (the node moving most), ``(d,)``."""
        u = self.x[k] - self.problem.body.rest_positions
        return u[int(np.argmax(np.linalg.norm(u, axis=1)))]

    def facts(self) -> dict:
        """The solid keys of ``result.json`` (documented in docs/solids.md)."""
        spec, body = self.case.spec, self.problem.body
        u = self.x[-1] - body.rest_positions
        fields = self.fields(len(self.x) - 1)
        inverted = body.inverted(self.x[-1])
        return {
            "mesh": {"dim": body.dim, "points": int(body.n), "cells": int(body.rest.n_cells),
                     "cell_type": "tetra" if body.dim == 3 else "triangle",
                     "element": body.element,
                     "fixed_dofs": int(len(self.problem.dirichlet().dofs))},
            "materials": [{"model": m.name, "mu": m.mu, "lam": m.lam, "E": m.young,
                           "nu": m.poisson, "density": m.density} for m in body.materials],
            "mode": "static" if spec.static else "dynamic",
            "integrator": None if spec.integrator is None else spec.integrator.to_dict(),
            "static": None if spec.static is None else {
                "load_steps": spec.static.load_steps, "project": spec.static.project},
            "linear_solver": spec.solver.to_dict(),
            "dt": spec.dt, "t_end": spec.t_end, "steps": int(self.steps),
            "steps_planned": spec.steps,
            "frames": len(self.x) if self.frames_written is None else self.frames_written,
            "times": [float(t) for t in self.times],
            "energies": [dict(e) for e in self.energies],
            "load_steps": [{"load_factor": r.load_factor, "iterations": r.iterations,
                            "substeps": r.substeps,
                            "residuals": list(map(float, r.residuals)),
                            "converged": r.converged} for r in self.records],
            "max_displacement": float(np.linalg.norm(u, axis=1).max()),
            "tip_displacement": [float(c) for c in self.tip()],
            "volume": {"rest": float(body.rest.volumes.sum()),
                       "final": float((body.rest.volumes * fields["J"]).sum())},
            "von_mises_max": (float(np.nanmax(fields["von_mises"]))    # None: every element inverted
                              if np.isfinite(fields["von_mises"]).any() else None),
            "stretch_range": [float(fields["principal_stretches"].min()),
                              float(fields["principal_stretches"].max())],
            "inverted_elements": int(len(inverted)),
            "interrupted": self.interrupted is not None,
            "verdict": self.verdict, "converged": self.converged, "failure": self.failure,
            "warnings": list(self.warnings),
            "residual_history": self.residual_history,
            "stats": dict(self.stats),
            "wall_time": float(self.wall_time), "timings": dict(self.timings),
            "files": list(self.files),
            **({} if self.contact is None else {"contact": self.contact.facts()}),
        }

    def summary_lines(self) -> list[str]:
        d = self.to_dict()
        m = d["mesh"]
        mats = ", ".join(f"{x['model']} (E {x['E']:.4g}, nu {x['nu']:.3g})" for x in d["materials"])
        cut = [f"{i} in {r['substeps']}" for i, r in enumerate(d["load_steps"], 1)
               if r["substeps"] > 1]
        how = (f"static, {d['static']['load_steps']} load steps, "
               f"{sum(r['iterations'] for r in d['load_steps'])} Newton iterations"
               + (f"; cut into sub-steps where the whole increment inverted elements: load step "
                  f"{', '.join(cut)}" if cut else "")
               if d["mode"] == "static" else
               f"{d['integrator']['method']}, dt {d['dt']:.4g}, t_end {d['t_end']:.4g}")
        stopped = f" (interrupted by {self.interrupted})" if self.interrupted else ""
        e = d["energies"][-1]
        lines = [f"solid     {self.case.name}: {m['cells']} "
                 f"{'' if m['element'] == 'P1' else m['element'] + ' '}{m['cell_type']} cells, "
                 f"{m['points']} nodes ({m['dim']}D), {mats}",
                 f"method    {how}",
                 f"result    max displacement {d['max_displacement']:.6g}, tip "
                 f"[{', '.join(f'{c:.6g}' for c in d['tip_displacement'])}], volume "
                 f"{d['volume']['final'] / d['volume']['rest'] - 1:+.3%}, von Mises max "
                 + (f"{d['von_mises_max']:.4g}" if d["von_mises_max"] is not None else
                    "- (every element inverted)"),
                 f"energy    elastic {e['elastic']:.6g}, kinetic {e['kinetic']:.6g}, gravity "
                 f"{e['gravity']:.6g}, load {e['load']:.6g} (last frame of {d['frames']})",
                 f"steps     {d['steps']} of {d['steps_planned']} "
                 f"{'load' if d['mode'] == 'static' else 'time'} steps{stopped}, "
                 f"{d['frames']} frames",
                 f"verdict   {self.verdict}" + (f": {self.failure}" if self.failure else ""),
                 self.timings_line()]
        if self.contact is not None:
            lines.append(self.contact.summary_line())
        if self.output_dir is not None:
            lines.append(self.output_line())
        return lines


# ----------------------------------------------------------------------------- run

def _run_static(case, problem: SolidProblem, stop) -> dict:
    """The load steps by :func:`femkit.solids.solve_static`, each equilibrium kept as a frame;
    a failure (Newton, a linear solve) keeps the frames before it."""
    from ...solids import solve_static

    spec, body = case.spec, problem.body
    st = spec.static
    K = st.load_steps
    x = body.rest_positions.copy()
    out = {"times": [0.0], "x": [x], "v": [np.zeros_like(x)],
           "energies": [frame_energies(problem, x)], "records": []}

    def keep(rec, x):
        out["records"].append(rec)
        out["times"].append(rec.load_factor)
        out["x"].append(x)
        out["v"].append(np.zeros_like(x))
        out["energies"].append(frame_energies(problem, x, load_factor=rec.load_factor))

    barrier = None
    if spec.contact is not None:
        out["contact"] = solid_contact(spec.contact, x, body)
        barrier = out["contact"].model
    try:
        solve_static(body, problem.dirichlet(1.0), problem.traction + problem.weight,
                     load_steps=K, project=st.project, rtol=st.rtol,
                     max_iterations=st.max_iterations, linear_solver=spec.solver,
                     on_step=keep, stop=stop, contact=barrier)
    except SolverError as exc:   # Newton or a linear solve failed: the load steps before are kept
        k = len(out["records"]) + 1
        out["failure"] = (f"load step {k}/{K} (load factor {k / K:g}): " + " ".join(str(exc).split()))
        out["verdict"] = "newton_failed" if isinstance(exc, EquilibriumError) else "solver_failed"
        record = getattr(exc, "record", None)
        history = [float(r) for s in (record.steps if record else []) for r in s.residuals]
        out["residual_history"] = history or None
    out["stopped"] = "failure" not in out and len(out["records"]) < K
    out["steps"] = len(out["records"])
    return out


def solid_contact(contact, x0, body):
    """The barrier contact force of a solid's ``contact:`` mapping on its boundary surface; the
    initial state checked (one line naming a pair of intersecting elements, CaseFileError)."""
    from ...contact.barrier import BarrierModel

    try:
        force = build_contact(contact, x0, body.rest.cells)
        force.model = BarrierModel(np.asarray(x0, float).reshape(body.n, body.dim), force.surface,
                                   force.obstacles, **force.options)
        force.model.check_intersection_free(x0)
    except CaseFileError:
        raise
    except InputError as exc:
        raise CaseFileError(str(exc)) from None
    return force


def _run_dynamic(case, problem: SolidProblem, stop, progress) -> dict:
    from ...dynamics.forces.elastic import DeadLoad
    from ...dynamics.system import elastic_system
    from ...dynamics.forces.gravity import Gravity
    from ...dynamics.integrators import StepContext
    from ...dynamics.simulate import simulate
    from .cost import check_explicit_step

    spec, body = case.spec, problem.body
    forces = [Gravity(problem.gravity)] if spec.gravity is not None else []
    if np.any(problem.traction):
        forces.append(DeadLoad(problem.traction))
    v0 = None
    if spec.velocity is not None:
        v0 = np.broadcast_to(np.asarray(spec.velocity, float), (body.n, body.dim)).copy()
    if spec.bodies is not None:   # each body's velocity on its nodes
        v0 = np.zeros((body.n, body.dim))
        cells, tags = np.asarray(problem.mesh.cells), np.asarray(problem.mesh.cell_tags)
        for k, b in enumerate(spec.bodies):
            if b["velocity"] is not None:
                v0[np.unique(cells[tags == k + 1])] = np.asarray(b["velocity"], float)[:body.dim]
    # every fixed or roller component is held where its displacement puts it, from t = 0
    bc = problem.dirichlet(1.0)
    held = np.zeros(body.ndof, dtype=bool)
    held[bc.dofs] = True
    x0 = body.rest_positions.reshape(-1).copy()
    x0[bc.dofs] += bc.values
    system = elastic_system(body, x0=x0.reshape(body.n, body.dim), v0=v0,
                            pinned=held.reshape(body.n, body.dim), forces=forces)
    if spec.contact is not None:
        system.attach(solid_contact(spec.contact, system.x0, body))
        out_contact = system.forces[-1]
    else:
        out_contact = None
    check_explicit_step(case, system)    # a step that can only blow up: refused, nothing written
    out: dict = {} if out_contact is None else {"contact": out_contact}
    try:
        traj = simulate(system, spec.integrator.build(), spec.dt, spec.t_end,
                        ctx=StepContext(spec.solver), record_every=spec.output.every,
                        progress=progress, stop=stop)
    except InstabilityError as exc:
        traj = exc.partial
        out["failure"] = " ".join(str(exc).split())
    except SolverError as exc:   # a step failed (Newton, a linear solve): the frames before are kept
        traj = getattr(exc, "partial", None)
        if traj is None:
            raise
        out["failure"] = " ".join(str(exc).split())
        out["verdict"] = "newton_failed" if isinstance(exc, EquilibriumError) else "solver_failed"
        out["residual_history"] = getattr(exc, "residuals", None)
    out.update(times=list(traj.times), x=list(traj.x), v=list(traj.v),
               energies=[frame_energies(problem, x, v) for x, v in zip(traj.x, traj.v)],
               records=[], stats=dict(traj.stats), stopped=bool(traj.interrupted),
               steps=int(traj.steps))
    return out


def _say_compiling(case, echo: Callable[[str], Any]) -> None:
    """Say so when the run's materials must be generated and compiled first (a minute or so)."""
    from ...warmup_registry import COMPILE_MESSAGE

    pending = [m for m in dict(case.spec.materials).values() if not m.kernels_cached()]
    if pending:
        names = sorted({f"energy {m.energy.describe()[:60]}" if getattr(m, "energy", None)
                        else "the built-in materials" for m in pending})
        echo(f"{COMPILE_MESSAGE}: {'; '.join(names)}...")


def run_solid(case, output_dir: str | os.PathLike | None = None, quiet: bool = False,
              write: bool = True, echo: Callable[[str], Any] | None = None) -> SolidResult:
    """Run a prepared solid case: build, solve (static or dynamic), write, print the summary.

    A stop request (``case.options.stop``, set by SIGINT/SIGTERM under ``femkit solve``)
    during the meshing stops at once (nothing written); during the solve it ends the run after
    the current time step or Newton iteration, and the frames so far are written with
    ``interrupted: true`` (no pictures); during the output the frames written so far are kept,
    the pictures skipped. Warnings raised during the solve are kept in ``result.json`` and
    printed as ``femkit: warning: ...`` lines.

    Returns
    -------
    SolidResult
        ``converged`` false when Newton failed in a load step or the integration became
        unstable; the frames before are kept and written. ``interrupted`` names the signal that
        stopped it.
    """
    from ...interrupt import raising
    from ...progress import Progress
    from ...timing import WallClock
    from .cost import check_solid_fits

    clock = WallClock()
    if write:
        check_output_dir(output_dir or case.spec.output.dir, EARLIER_RUN)
    check_solid_fits(case)
    timer = StageTimer()
    t0 = time.perf_counter()
    if not quiet:
        _say_compiling(case, echo or print)
    with raising("meshing"), timer("build"):
        problem = build_problem(case)
    stop = case.options.stop
    with timer("solve"), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if case.spec.static is not None:
            run = _run_static(case, problem, stop)
        else:
            progress = Progress(case.spec.steps, f"solid {case.name}", unit="step", quiet=quiet)
            run = _run_dynamic(case, problem, stop, progress)
    messages = list(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))
    failure = run.get("failure")
    result = SolidResult(case=case, problem=problem, times=np.asarray(run["times"], float),
                         x=run["x"], v=run["v"], energies=run["energies"],
                         records=run["records"], failure=failure,
                         residual_history=run.get("residual_history"),
                         verdict=_verdict(case, run, stop), wall_time=time.perf_counter() - t0,
                         timings=timer.times, stats=run.get("stats", {}),
                         steps=run["steps"], stopped=stop.name if run.get("stopped") else None, warnings=messages)
    if run.get("contact") is not None:   # every frame: distances, pairs, the independent check
        result.contact = ContactRecorder(run["contact"])
        result.contact_forces = [result.contact.record(t, x)["contact_force"]
                                 for t, x in zip(result.times, result.x)]
    for w in () if quiet else messages:
        print(f"femkit: warning: {w}", file=sys.stderr)
    if write:
        from .output import write_solid_outputs

        with timer("output"):
            write_solid_outputs(result, output_dir or case.spec.output.dir)
    if failure is not None and (write or not quiet):  # a caller keeping nothing says it itself
        print(f"femkit: {result.verdict.replace('_', ' ')}: {failure}", file=sys.stderr)
    if not quiet:
        for line in result.summary_lines() + [clock.summary(result.timings)]:
            (echo or print)(line)
    return result


def _verdict(case, run: dict, stop) -> str:
    """``converged``, the failure's verdict, or ``interrupted`` (a solve stopped early)."""
    if run.get("failure") is not None:
        return run.get("verdict") or ("newton_failed" if case.spec.static else "unstable")
    return "interrupted" if run.get("stopped") else "converged"
