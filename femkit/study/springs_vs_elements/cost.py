"""The cost of a ``springs_vs_elements`` study before it runs (``--dry-run``, budgets)."""

from __future__ import annotations

from ...cost import Plan, Stage
from ..cost import runs_plan

__all__ = ["plan"]


def plan(study) -> Plan:
    """The plan of a ``springs_vs_elements`` study: per scene, every method on every mesh size
    (``repeats`` times, triangles from the geometry's measure, springs ~1.5 per triangle, two
    layouts' worth for ``edges_cross``) and the reference on its finer mesh, each priced as
    implicit steps (:func:`femkit.study.prices.implicit_run_seconds`)."""
    from ...case.cost import geometry_domain
    from ...cost import predict_triangles
    from ..prices import implicit_run_seconds
    from .scenes import SVSE_SCENES

    d = study.spec
    stages, runs = [], 0
    for name, p in d.scenes.items():
        geo, params = SVSE_SCENES.get(name).geometry(p)
        _, area, length = geometry_domain(geo, params)
        steps = float(p["t_end"]) / float(p["dt"])

        def price(method, h):
            tri = predict_triangles(area, length, h)
            nodes = tri / 2.0 + length / h / 2.0
            parts = tri if not method.springs else 1.5 * tri * (2 if method.layout ==
                                                                 "edges_cross" else 1)
            return implicit_run_seconds(steps, nodes=nodes, parts=parts,
                                        integrator=method.integrator.method,
                                        elements=not method.springs)

        seconds = price(d.reference, float(p["reference_h"]))
        seconds += sum(d.repeats * price(m, float(h)) for m in d.methods for h in p["h"])
        if d.warmup:
            seconds += sum(price(m, max(p["h"])) * 2.0 / steps for m in d.methods)
        n = len(d.methods) * len(p["h"]) + 1
        runs += n
        stages.append(Stage(name, seconds, 0.0, detail=f"{len(d.methods)} methods x "
                            f"{len(p['h'])} mesh sizes + reference at h {p['reference_h']:g}, "
                            f"{steps:,.0f} steps each"))
    return runs_plan(study, stages, runs, [
        "triangles from the geometry's measure (gmsh); each run priced as implicit steps of the "
        "scene model times the integrator's solves per step (femkit/study/prices.py); an "
        "order of magnitude"])
