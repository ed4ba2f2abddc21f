"""``kind: springs_vs_elements``: mass-spring bodies against finite elements on the same meshes.

Every method of ``methods:`` (springs in a layout of
:data:`~femkit.study.springs_vs_elements.layouts.SPRING_LAYOUTS` with Van Gelder's stiffness, or elements of a
material of :data:`femkit.solids.MATERIALS`, each with its integrator: Newton's implicit Euler,
projective dynamics, fast mass-spring, ...) runs every scene of ``scenes:``
(:data:`~femkit.study.springs_vs_elements.scenes.SVSE_SCENES`: the hanging beam, the falling disk) on gmsh
meshes of every ``h``, with the same lumped masses, supports, forces, ``dt`` and ``t_end``.
The reference is the ``reference`` material (stable neo-Hookean) integrated by Newton on the
scene's finer ``reference_h`` mesh.

Measured per run (one record): the tracked quantity's trajectory error
``max_t |q(t) - q_ref(t)| / max_t |q_ref(t) - q_ref(0)|`` (the work-precision error), the
relative error of the scene's value (the beam's settled tip deflection, the disk's peak
squash), the area change ``sum det F area / area_0 - 1`` over time and the relative error of its
peak, both errors fitted against ``h``, and the integration's wall time (minimum over
``repeats``). The report draws error against run time, the value and both errors against ``h``
with fitted rates, the area change over time and the two spring layouts on the same mesh
against the elements.
"""

from __future__ import annotations

import numpy as np

from ...errors import CaseFileError

__all__ = ["run", "trajectory_error", "topology_table"]


def trajectory_error(q, q_ref) -> float:
    """``max_t |q - q_ref| / max_t |q_ref - q_ref(0)|`` (same time grid)."""
    scale = float(np.max(np.abs(q_ref - q_ref[0])))
    return float(np.max(np.abs(np.asarray(q) - q_ref)) / max(scale, 1e-300))


#: what is fitted against h: the record key of the relative error, and its name in the report
FITTED = {"value_error": "the scene's value (settled tip deflection, peak squash)",
          "area_error": "the largest area change over the run"}


def _fits(records) -> list:
    """Per (scene, method) and per quantity of :data:`FITTED`: the rate of the relative error
    against ``h`` (positive errors only) and the ratio of the finest to the coarsest error (a
    stall keeps it near 1, a rate ``p`` makes it ``(h_min / h_max)^p``)."""
    from ..fit import fit_rate

    out = []
    keys = dict.fromkeys((r["scene"], r["method"]) for r in records)
    for scene, method in keys:
        rows = sorted((r for r in records if r["scene"] == scene and r["method"] == method),
                      key=lambda r: -r["h"])
        h = np.array([r["h"] for r in rows])
        for key in FITTED:
            e = np.array([r[key] for r in rows])
            ok = np.isfinite(e) & (e > 0)
            fit = fit_rate(h[ok], e[ok]) if ok.sum() >= 2 else None
            out.append({"scene": scene, "method": method, "fitted": key,
                        "slope": None if fit is None else fit.slope,
                        "intercept": None if fit is None else fit.intercept,
                        "r2": None if fit is None or not np.isfinite(fit.r2) else fit.r2,
                        "slope_stderr": None if fit is None or not np.isfinite(fit.slope_stderr)
                        else fit.slope_stderr, "n": int(ok.sum()),
                        "error_coarsest": float(e[0]), "error_finest": float(e[-1]),
                        "finest_over_coarsest": float(e[-1] / e[0]) if e[0] > 0 else None,
                        "fit": fit})
    return out


def _record(name, scene, m, h, run, ref) -> dict:
    """One run's row: sizes, time, the value and area change against the reference."""
    n = min(len(run.quantity), len(ref.quantity))
    value, value_ref = scene.summary(run.quantity[:n]), scene.summary(ref.quantity[:n])
    peak = _peak(run.area_change[:n])
    peak_ref = _peak(ref.area_change[:n])
    return {"scene": name, "method": m.label, "model": m.model, "layout": m.layout,
            "material": m.material, "integrator": m.integrator.method, "h": float(h),
            "nodes": run.nodes, "springs_or_elements": run.parts,
            "seconds": run.seconds, "completed": run.completed,
            "value": value, "reference_value": value_ref,
            "value_error": float(abs(value - value_ref) / abs(value_ref)),
            "trajectory_error": trajectory_error(run.quantity[:n], ref.quantity[:n]),
            "area_change_peak": peak, "reference_area_change_peak": peak_ref,
            "area_error": float(abs(peak - peak_ref) / max(abs(peak_ref), 1e-300)),
            "area_change_end": float(run.area_change[n - 1])}


def _peak(a) -> float:
    """The area change of largest magnitude over the run (signed)."""
    a = np.asarray(a, dtype=float)
    return float(a[int(np.argmax(np.abs(a)))])


def run(study, progress_enabled=None) -> dict:
    """Every (scene, method, h) run and each scene's reference; records, fits, tables."""
    from ...progress import Progress
    from .models import run_model
    from .scenes import SVSE_SCENES, scene_mesh

    spec = study.spec
    mat = dict(spec.material)
    total = sum(len(p["h"]) * len(spec.methods) + 1 for p in spec.scenes.values())
    bar = Progress(total, "springs_vs_elements", unit="run", quiet=progress_enabled is False)
    records, series, notes = [], {}, []
    for name, params in spec.scenes.items():
        scene = SVSE_SCENES.get(name)
        h_ref = float(params["reference_h"])
        ref = run_model(spec.reference, scene, params, scene_mesh(scene, params, h_ref), h_ref,
                        mat)
        bar.update()
        if not ref.completed:
            raise CaseFileError(f"scenes.{name}: the reference run stopped: {ref.reason}")
        series[(name, "reference", h_ref)] = ref
        if spec.warmup:   # compile what the methods use before timing them
            mesh = scene_mesh(scene, params, max(params["h"]))
            for m in spec.methods:
                run_model(m, scene, {**params, "t_end": 2 * float(params["dt"])}, mesh,
                          max(params["h"]), mat)
        for h in sorted(params["h"], reverse=True):
            mesh = scene_mesh(scene, params, h)
            for m in spec.methods:
                run = run_model(m, scene, params, mesh, h, mat, repeats=spec.repeats)
                series[(name, m.label, float(h))] = run
                records.append(_record(name, scene, m, h, run, ref))
                if not run.completed:
                    notes.append(f"{name}, {m.label}, h = {h:g}: stopped early ({run.reason})")
                bar.update()
    bar.close()
    fits = _fits(records)
    topo = topology_table(records)
    return {"records": records, "fits": fits, "notes": notes, "series": series,
            "tables": {"topology": topo}}


def topology_table(records) -> list:
    """Per scene and mesh size: each spring layout's value, their spread relative to the
    reference value, and the elements' (Newton) value on the same mesh."""
    out = []
    for scene in dict.fromkeys(r["scene"] for r in records):
        for h in sorted({r["h"] for r in records if r["scene"] == scene}, reverse=True):
            rows = [r for r in records if r["scene"] == scene and r["h"] == h]
            springs = {r["method"]: r["value"] for r in rows if r["model"] == "springs"}
            ref = rows[0]["reference_value"]
            vals = np.array(list(springs.values()))
            elements = [r for r in rows if r["model"] == "elements" and r["integrator"] == "newton"]
            out.append({"scene": scene, "h": h, **{f"value {k}": v for k, v in springs.items()},
                        "springs_spread": float((vals.max() - vals.min()) / abs(ref))
                        if len(vals) > 1 else None,
                        "elements_value": elements[0]["value"] if elements else None,
                        "reference_value": ref})
    return out

