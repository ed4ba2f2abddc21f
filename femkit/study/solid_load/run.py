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

from .spec import base_case, tip_traction

__all__ = ["run", "elastica_deflection", "material_cases"]


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
    from ...case import load_case

    if base is None:
        path, base = base_case(study)
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
    from ...case.load import case_from_dict, read_yaml

    rest = _base_material(base)
    data = dict(read_yaml(path))
    data["material"] = {"model": name, "mu": rest.mu, "lam": rest.lam, "density": rest.density}
    over = {k: v for k, v in over.items() if k != "material"}
    return case_from_dict(data, path.parent, name=path.stem, path=path, **over)


def _base_material(base):
    """The base case's material (the one of the whole body)."""
    return dict(base.spec.materials)[None]


def run(study, progress_enabled=None) -> dict:
    """One record per (material, load step): load, ``alpha``, tip deflection, ratios."""
    from ...solids.boundary import tagged_nodes
    from ...progress import Progress

    path, base = base_case(study)
    d = study.spec
    trac = tip_traction(base)
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

