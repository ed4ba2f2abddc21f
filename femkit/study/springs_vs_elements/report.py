"""Figures and report of the ``springs_vs_elements`` study (matplotlib, Agg, imported lazily).

Per scene: error against run time (the work-precision plot of the other studies,
:func:`femkit.study.figures.work_precision_figure`), the scene's value (settled tip deflection, peak
squash), its error and the peak area change's error against the mesh size with fitted rates; over both scenes: the area change over time and
the two spring layouts against the elements on the same mesh. One :class:`StyleBook` keeps a
method's colour and marker the same in every figure.
"""

from __future__ import annotations

import numpy as np

__all__ = ["build", "summary", "convergence_figure", "time_panels_figure"]

_FAMILY = {"springs": "--", "elements": "-"}


def _book():
    from ..figures import StyleBook

    return StyleBook(_FAMILY)


def _methods(records, scene):
    return list(dict.fromkeys(r["method"] for r in records if r["scene"] == scene))


def convergence_figure(path, records, fits, scene: str, label: str, book, title: str) -> str:
    """Left: the scene's value against ``h`` per method with the reference drawn flat; middle:
    its relative error against ``h`` (log-log) with the fitted rate dotted; right: the same for
    the peak area change."""
    from ...io.figures import new_figure, save_figure
    from ..figures import _readable_log_ticks

    fig = new_figure(15.0, 4.6, layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    ref = None
    for m in _methods(records, scene):
        rows = sorted((r for r in records if r["scene"] == scene and r["method"] == m),
                      key=lambda r: r["h"])
        model = rows[0]["model"]
        st = book(m, model)
        h = np.array([r["h"] for r in rows])
        ax1.plot(h, [r["value"] for r in rows], label=m, **st)
        for ax, key in ((ax2, "value_error"), (ax3, "area_error")):
            e = np.array([r[key] for r in rows])
            ok = e > 0
            fit = next((f for f in fits if f["scene"] == scene and f["method"] == m
                        and f["fitted"] == key), None)
            lab = m if fit is None or fit["slope"] is None else f"{m}  (rate {fit['slope']:.2f})"
            ax.plot(h[ok], e[ok], label=lab, **st)
            if fit is not None and fit.get("fit") is not None:
                ax.plot(h[ok], fit["fit"].predict(h[ok]), color=st["color"], linestyle=":",
                        linewidth=1.0)
        ref = rows[0]["reference_value"]
    if ref is not None:
        ax1.axhline(ref, color="k", linestyle="--", linewidth=1.4,
                    label="reference (finest mesh, neo-Hookean, Newton)")
    for ax in (ax1, ax2, ax3):
        ax.set_xscale("log")
        ax.invert_xaxis()
        ax.set_xlabel("mesh size h (finer to the right)")
        ax.grid(True, which="both", alpha=0.3)
    for ax in (ax2, ax3):
        ax.set_yscale("log")
    for ax in (ax1, ax2, ax3):
        _readable_log_ticks(ax)
    ax1.set_ylabel(label)
    ax1.set_title(f"{label} against mesh size", fontsize=10)
    ax2.set_ylabel("relative error against the reference")
    ax2.set_title("its error, with fitted rates", fontsize=10)
    ax3.set_ylabel("relative error of the peak area change")
    ax3.set_title("volume: error of the peak area change", fontsize=10)
    for ax in (ax1, ax2, ax3):
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=11)
    return str(save_figure(fig, path, dpi=100))


def time_panels_figure(path, panels, book, title: str, ylabel) -> str:
    """One panel per scene: curves ``(label, model, t, y)`` against time; the reference black."""
    from ...io.figures import new_figure, save_figure

    fig = new_figure(5.5 * len(panels) + 0.5, 4.3, layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(panels)))
    for ax, (name, curves, lab) in zip(axes, panels):
        for label, model, t, y in curves:
            if model == "reference":
                ax.plot(t, y, color="k", linestyle="--", linewidth=1.6, label=label)
                continue
            st = book(label, model)
            st.update(markevery=max(1, len(t) // 10), markersize=4)
            ax.plot(t, y, label=label, **st)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(lab if ylabel is None else ylabel)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=11)
    return str(save_figure(fig, path, dpi=100))


def build(report, study, result, data, stage) -> None:
    """The kind's report: what was compared, the four kinds of figures, the tables."""
    from ..figures import work_precision_figure
    from ..pareto import pareto_front
    from .layouts import SPRING_LAYOUTS
    from .scenes import SVSE_SCENES

    spec = study.spec
    recs, fits, series = result.records, result.fits, data["series"]
    mat = spec.material
    book = _book()
    report.paragraph(
        f"Material E = {mat['E']:g}, nu = {mat['nu']:g}, density {mat['density']:g} (2D, plane "
        "strain for the elements, thickness 1). Springs: stiffness fitted from E by Van "
        "Gelder's rule k = E' A / L^2 (Van Gelder 1998; E' = E / (1 - nu^2), A the area of "
        "the triangles the spring spans); the same lumped masses, supports, forces and time "
        "step for every method. Layouts: " + "; ".join(
            f"`{n}`: {SPRING_LAYOUTS.get(n).description}" for n in SPRING_LAYOUTS.names())
        + f". Reference: {spec.reference.label} on each scene's finer reference mesh.")
    report.heading("Error against run time")
    for name in spec.scenes:
        scene = SVSE_SCENES.get(name)
        rows = [r for r in recs if r["scene"] == name]
        front = pareto_front([r["seconds"] for r in rows], [r["trajectory_error"] for r in rows])
        ser = []
        for m in _methods(recs, name):
            mr = sorted((r for r in rows if r["method"] == m), key=lambda r: -r["h"])
            ser.append({"label": m, "x": [r["seconds"] for r in mr],
                        "y": [r["trajectory_error"] for r in mr],
                        "style": book(m, mr[0]["model"])})
        work_precision_figure(stage / f"figures/work_precision_{name}.png", ser,
                              front=[(rows[i]["seconds"], rows[i]["trajectory_error"])
                                     for i in front],
                              title=f"{name}: {scene.label}, error over the run against time",
                              ylabel="max_t |q - q_ref| / max_t |q_ref - q_ref(0)|")
        report.figure(f"figures/work_precision_{name}.png",
                      f"{name} ({scene.description}): trajectory error of the {scene.label} "
                      "against the integration's wall time, one point per mesh size "
                      "(coarse to fine along each line)")
    report.heading("Convergence with the mesh size")
    for name in spec.scenes:
        scene = SVSE_SCENES.get(name)
        convergence_figure(stage / f"figures/convergence_{name}.png", recs, fits, name,
                           scene.value_label, book, f"{name}: {scene.value_label} against h")
        report.figure(f"figures/convergence_{name}.png",
                      f"{name}: the {scene.value_label} and its error against the reference, "
                      "and the error of the peak area change, with the rates fitted over the "
                      "swept meshes")
    cols = ["scene", "method", "fitted", "slope", "r2", "error_coarsest", "error_finest",
            "finest_over_coarsest"]
    report.table(cols, [[f[c] for c in cols] for f in fits],
                 caption="Fitted rates of the relative errors against h (value_error: the "
                         "scene's value; area_error: the peak area change)")

    def finest(name):
        return min(float(h) for h in spec.scenes[name]["h"])

    def ref_of(name):
        return next(v for (s, m, _), v in series.items() if s == name and m == "reference")

    report.heading("Volume (area) change over time")
    panels = []
    for name in spec.scenes:
        hf = finest(name)
        curves = [(m, recs_model(recs, name, m), series[(name, m, hf)].times,
                   100.0 * series[(name, m, hf)].area_change) for m in _methods(recs, name)]
        ref = ref_of(name)
        curves.append(("reference", "reference", ref.times, 100.0 * ref.area_change))
        panels.append((f"{name}, h = {hf:g}", curves, "area change [%]"))
    time_panels_figure(stage / "figures/volume.png", panels, book,
                       "Area change sum(det F area) / area_0 - 1 over time", None)
    report.figure("figures/volume.png", "Area change over time on the finest swept mesh of "
                                        "each scene (the reference dashed)")
    report.heading("Topology: two spring layouts on the same mesh")
    panels = []
    for name in spec.scenes:
        hf = finest(name)
        keep = [m for m in _methods(recs, name)
                if recs_model(recs, name, m) == "springs" or
                next(r for r in recs if r["scene"] == name and r["method"] == m)["integrator"]
                == "newton"]
        curves = [(m, recs_model(recs, name, m), series[(name, m, hf)].times,
                   series[(name, m, hf)].quantity) for m in keep]
        ref = ref_of(name)
        curves.append(("reference", "reference", ref.times, ref.quantity))
        panels.append((f"{name}, h = {hf:g}", curves, SVSE_SCENES.get(name).label))
    time_panels_figure(stage / "figures/topology.png", panels, book,
                       "Spring layouts against elements, same mesh", None)
    report.figure("figures/topology.png", "The tracked quantity over time for each spring "
                                          "layout and the elements on the same mesh")
    topo = result.tables.get("topology", [])
    if topo:
        cols = list(dict.fromkeys(k for t in topo for k in t))
        report.table(cols, [[t.get(c) for c in cols] for t in topo],
                     caption="Final values per mesh size: spring layouts and elements")
    report.heading("Every run")
    cols = ["scene", "method", "h", "nodes", "springs_or_elements", "seconds", "value",
            "value_error", "trajectory_error", "area_change_peak", "area_error", "completed"]
    report.table(cols, [[r[c] for c in cols] for r in recs])


def recs_model(records, scene, method) -> str:
    """The model (``springs`` / ``elements``) of a method's runs."""
    return next(r["model"] for r in records if r["scene"] == scene and r["method"] == method)


def summary(result) -> list[str]:
    """One line per (scene, method) at the finest mesh: value and area errors with their rates
    against h, seconds; then the spread of the spring layouts."""
    out = []
    for scene, method in dict.fromkeys((r["scene"], r["method"]) for r in result.records):
        rows = [r for r in result.records if r["scene"] == scene and r["method"] == method]
        last = min(rows, key=lambda r: r["h"])

        def rate(key):
            f = next(f for f in result.fits if f["scene"] == scene and f["method"] == method
                     and f["fitted"] == key)
            return "-" if f["slope"] is None else f"{f['slope']:.2f}"

        out.append(f"{scene}: {method}: value error {last['value_error']:.2%} at h {last['h']:g} "
                   f"(rate {rate('value_error')}), trajectory error "
                   f"{last['trajectory_error']:.2%}, peak area change "
                   f"{last['area_change_peak']:+.2%} (reference "
                   f"{last['reference_area_change_peak']:+.2%}, rate {rate('area_error')}), "
                   f"{last['seconds']:.2f} s")
    for t in result.tables.get("topology", []):
        if t["springs_spread"] is not None and t["h"] == min(
                r["h"] for r in result.tables["topology"] if r["scene"] == t["scene"]):
            out.append(f"{t['scene']}: the spring layouts differ by {t['springs_spread']:.2%} of "
                       f"the reference value at h {t['h']:g}")
    return out
