"""``kind: solid_load``: a cantilever under a growing tip load, one curve per material.

The base case is a ``problem: solid`` file (static, a ``beam`` geometry clamped at one end with a
traction on its tip face, e.g. cases/solid_cantilever.yaml). Every material of ``materials:``
(names of :data:`femkit.solids.MATERIALS`, the case's ``E``, ``nu``, ``density`` kept) runs the
case with its tractions and gravity multiplied by ``scale`` in ``load_steps`` equal load steps
(:func:`femkit.case.solid.run.run_solid`, each load step a frame). The tracked quantity is the
mean displacement of the loaded face's nodes along the load (the tip deflection).

Theory drawn with the curves: linear beam theory ``delta = P L^3 / (3 E I)`` and the elastica of
an inextensible Euler-Bernoulli cantilever under a dead tip load (Bisshopp & Drucker 1945, Quart.
Appl. Math. 3: 272), solved here by shooting on ``EI theta'' = -P cos(theta)``, ``theta(0) = 0``,
``theta'(L) = 0``. Both are plotted as ``delta / delta_linear`` against the load parameter
``alpha = P L^2 / (E I)``, the finite-element curves divided by the linear material's deflection
on the same mesh (which removes the P1 tetrahedra's bending stiffness error, the same factor for
every material at small strain). Expected: the linear material stays at 1 (its energy is
quadratic in ``u``: no geometric nonlinearity); the rotation-invariant materials follow the
elastica down (the tip moves inward, the moment arm shortens); at large strain St. Venant-Kirchhoff
softens on the compressed side (its stress peaks at stretch ``1/sqrt(3)``) and deflects more than
co-rotational and neo-Hookean, or loses equilibrium.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from ..errors import CaseFileError

__all__ = ["solid_load_schema", "check_solid_load", "run_solid_load", "build_solid_load_report",
           "solid_load_summary", "elastica_deflection", "material_cases"]


def solid_load_schema() -> dict:
    """The kind's own keys (``materials`` enum from :data:`femkit.solids.MATERIALS`)."""
    from ..solids import MATERIALS

    return {
        "base_case": {"type": "string", "description": "a static solid case (beam, tip traction)"},
        "materials": {"type": "array", "minItems": 1, "uniqueItems": True,
                      "items": {"enum": MATERIALS.names()},
                      "default": ["linear", "corotational", "stvk", "stable_neo_hookean"]},
        "scale": {"type": "number", "exclusiveMinimum": 0, "default": 1.0,
                  "description": "multiplies the base case's tractions and gravity"},
        "load_steps": {"type": "integer", "minimum": 1, "default": 10},
        "case_overrides": {"type": "object", "default": {},
                           "description": "merged into the base case (e.g. mesh: {h: 0.5})"},
    }


def _base(study):
    from ..case import load_case

    d = study.spec
    path = study.resolve(d.base_case)
    if not path.is_file():
        raise CaseFileError(f"base_case: file not found: {path}")
    return path, load_case(path, **dict(d.case_overrides))


def _traction(case) -> tuple:
    tractions = [b for b in case.spec.boundaries if b.kind == "traction"]
    if len(tractions) != 1 or case.spec.static is None or case.spec.mesh.get("geometry") != "beam":
        raise CaseFileError("base_case: needs a static solid case on the 'beam' geometry with one "
                            "traction boundary (the loaded tip)")
    return tractions[0]


def check_solid_load(study) -> None:
    """Build ``study.spec`` (:class:`femkit.study.spec.SolidLoadStudySpec`), load the base case
    now (its own checks), and check it is a loaded cantilever."""
    from .spec import SolidLoadStudySpec

    study.spec = SolidLoadStudySpec.from_data(study.data)
    path, case = _base(study)
    if case.problem != "solid":
        raise CaseFileError(f"base_case: {path.name} is not a solid case (problem: solid)")
    _traction(case)
    study.files.append(path)


def elastica_deflection(alpha: float) -> float:
    """Tip deflection ``delta / L`` along the load of an inextensible cantilever under a dead tip
    load with ``alpha = P L^2 / (E I)`` (the elastica; ``alpha / 3`` for small ``alpha``).

    >>> round(elastica_deflection(1.0), 3), round(elastica_deflection(1e-6) / 1e-6, 6)
    (0.302, 0.333333)
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    if alpha <= 0:
        return 0.0

    def shoot(k0):  # theta'(0) = k0; returns theta'(1) and the deflection, s in [0, 1]
        sol = solve_ivp(lambda s, y: [y[1], -alpha * math.cos(y[0]), math.sin(y[0])], (0.0, 1.0),
                        [0.0, k0, 0.0], rtol=1e-11, atol=1e-12)
        return sol.y[1, -1], sol.y[2, -1]

    k0 = brentq(lambda k: shoot(k)[0], 0.0, alpha, xtol=1e-13)   # theta'(0) = M(0)/EI <= alpha
    return float(shoot(k0)[1])


def material_cases(study, path=None, base=None):
    """``(material name, case)`` for each material of the study: the base case with its
    tractions and gravity times ``scale`` in ``load_steps`` load steps (the sweep's runs, and
    the cases the cost plan prices)."""
    from ..case import load_case

    if base is None:
        path, base = _base(study)
    d = study.spec
    mat = base.data["material"]
    designed = "energy" in mat   # a designed energy: each material gets its moduli at rest
    static = base.data["static"] if isinstance(base.data["static"], dict) else {}
    for name in d.materials:
        over = {**d.case_overrides, "material": {**mat, "model": name},
                "static": {**static, "load_steps": d.load_steps},
                "boundaries": [{**b, "traction": list(np.asarray(b["traction"]) * d.scale)}
                               if b["type"] == "traction" else dict(b)
                               for b in base.data["boundaries"]]}
        if "gravity" in base.data:
            over["gravity"] = list(np.asarray(base.data["gravity"]) * d.scale)
        if designed:
            yield name, _with_material(path, base, name, over)
        else:
            yield name, load_case(path, **over)


def _with_material(path, base, name: str, over: dict):
    """The base case (a material designed by its energy) with the built-in material ``name`` of
    the same moduli at rest (``mu``, ``lam``) and density in its place, and ``over`` merged."""
    from ..case.load import case_from_dict, read_yaml

    rest = _base_material(base)
    data = dict(read_yaml(path))
    data["material"] = {"model": name, "mu": rest.mu, "lam": rest.lam, "density": rest.density}
    over = {k: v for k, v in over.items() if k != "material"}
    return case_from_dict(data, path.parent, name=path.stem, path=path, **over)


def _base_material(base):
    """The base case's material (the one of the whole body)."""
    return dict(base.spec.materials)[None]


def run_solid_load(study, progress_enabled=None) -> dict:
    """One record per (material, load step): load, ``alpha``, tip deflection, ratios."""
    from ..solids.boundary import tagged_nodes
    from ..progress import Progress

    path, base = _base(study)
    d = study.spec
    trac = _traction(base)
    p = dict(base.spec.mesh.get("params") or {})
    L, W, H = (float(p.get(k, v)) for k, v in (("length", 5.0), ("width", 1.0), ("height", 1.0)))
    mat = base.data["material"]
    E = float(mat["E"]) if "E" in mat else _base_material(base).young
    I = W * H ** 3 / 12.0
    t = np.asarray(trac.traction, float) * d.scale
    direction = t / np.linalg.norm(t)
    P_total = float(np.linalg.norm(t)) * W * H          # a uniform traction on the W x H tip face
    records, notes = [], []
    bar = Progress(len(d.materials), "solid_load", unit="material",
                   quiet=progress_enabled is False)
    for name, case in material_cases(study, path, base):
        res = case.run(write=False, quiet=True)
        tip = tagged_nodes(res.problem.mesh, trac.tag)
        X = res.problem.body.rest_positions
        for k in range(1, len(res.x)):
            lam = float(res.times[k])
            rec = res.records[k - 1]
            records.append({
                "material": name, "load_factor": lam, "load": lam * P_total,
                "alpha": lam * P_total * L ** 2 / (E * I),
                "tip_deflection": float(((res.x[k][tip] - X[tip]) @ direction).mean()),
                "iterations": int(rec.iterations), "converged": True,
                "volume_change": float((res.problem.body.rest.volumes * res.fields(k)["J"]).sum()
                                       / res.problem.body.rest.volumes.sum() - 1.0)})
        if res.failure:
            notes.append(f"{name}: no equilibrium beyond load factor "
                         f"{res.times[-1]:.3g}: {res.failure}")
            if progress_enabled is not False:
                print(f"femkit: note: {name}: no equilibrium beyond load factor "
                      f"{res.times[-1]:.3g} ({res.verdict.replace('_', ' ')}); the study records "
                      "this as a result and goes on", file=sys.stderr)
        bar.update()
    bar.close()
    linear = {r["load_factor"]: r["tip_deflection"] for r in records if r["material"] == "linear"}
    for r in records:
        lin = linear.get(r["load_factor"])
        r["ratio_to_linear"] = None if not lin else r["tip_deflection"] / lin
        r["elastica_ratio"] = elastica_deflection(r["alpha"]) / (r["alpha"] / 3.0)
        r["beam_theory"] = r["load"] * L ** 3 / (3 * E * I)
    return {"records": records, "notes": notes}


def _figure(path, title: str, records) -> None:
    from ..io.figures import new_figure, save_figure

    fig = new_figure(9.5, 4.2)
    ax1, ax2 = fig.subplots(1, 2)
    alphas = np.linspace(1e-3, max(r["alpha"] for r in records), 60)
    ax2.plot(alphas, [elastica_deflection(a) / (a / 3.0) for a in alphas], color="black", lw=2,
             label="elastica (inextensible beam)")
    top = max(r["alpha"] for r in records)
    styles = ("-", "--", "-.", ":")
    for i, name in enumerate(dict.fromkeys(r["material"] for r in records)):
        rows = [r for r in records if r["material"] == name]
        if not rows:  # no equilibrium at the first load step: nothing to draw (see the notes)
            continue
        a = [0.0] + [r["alpha"] for r in rows]
        line, = ax1.plot(a, [0.0] + [abs(r["tip_deflection"]) for r in rows], marker="o", ms=3,
                         ls=styles[i % 4], label=name)
        if rows[0]["ratio_to_linear"] is not None:
            ax2.plot([r["alpha"] for r in rows], [r["ratio_to_linear"] for r in rows], marker="o",
                     ms=3, ls=styles[i % 4], color=line.get_color(), label=name)
        if rows[-1]["alpha"] < 0.999 * top:   # no equilibrium at the next load step
            last = rows[-1]
            for ax, y in ((ax1, abs(last["tip_deflection"])), (ax2, last["ratio_to_linear"])):
                if y is not None:
                    ax.plot([last["alpha"]], [y], marker="X", ms=11, color=line.get_color())
                    ax.annotate(f"{name}: no equilibrium\nbeyond alpha = {last['alpha']:.2g}",
                                (last["alpha"], y), xytext=(12, 14), textcoords="offset points",
                                fontsize=7, color=line.get_color(),
                                arrowprops={"arrowstyle": "-", "color": line.get_color()})
    rows = [r for r in records if r["material"] == records[0]["material"]]
    ax1.plot([0.0] + [r["alpha"] for r in rows], [0.0] + [r["beam_theory"] for r in rows],
             color="black", ls="--", lw=1, label="linear beam theory P L^3 / 3EI")
    ax1.set_xlabel("load parameter alpha = P L^2 / (E I)")
    ax1.set_ylabel("tip deflection along the load")
    ax1.set_title("tip deflection", fontsize=10)
    ax2.set_xlabel("load parameter alpha = P L^2 / (E I)")
    ax2.set_ylabel("deflection / linear material's deflection")
    ax2.set_title("geometric and material nonlinearity", fontsize=10)
    for ax, where in ((ax1, "upper left"), (ax2, "lower left")):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc=where)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path)


def build_solid_load_report(report, study, result, data, stage) -> None:
    report.paragraph("Tip deflection (mean displacement of the loaded face along the load) of a "
                     "clamped beam under a dead tip traction growing in equal load steps, one "
                     "curve per material with the same E, nu. Right: each material's deflection "
                     "divided by the linear material's on the same mesh, against the elastica's "
                     "ratio to linear beam theory.")
    _figure(stage / "figures/solid_load.png", study.title, result.records)
    report.figure("figures/solid_load.png", "Tip deflection against the load parameter, per "
                                            "material; the elastica and linear beam theory")
    cols = ["material", "load_factor", "alpha", "tip_deflection", "ratio_to_linear",
            "elastica_ratio", "iterations", "volume_change"]
    report.table(cols, [[r[c] for c in cols] for r in result.records])


def solid_load_summary(result) -> list[str]:
    out = []
    for name in dict.fromkeys(r["material"] for r in result.records):
        r = [x for x in result.records if x["material"] == name][-1]
        ratio = "" if r["ratio_to_linear"] is None else \
            f", {r['ratio_to_linear']:.3f} x linear (elastica {r['elastica_ratio']:.3f})"
        out.append(f"{name}: tip deflection {r['tip_deflection']:.4g} at alpha "
                   f"{r['alpha']:.3g}{ratio}")
    return out
