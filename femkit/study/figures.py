"""Study figures (matplotlib, Agg canvas, imported lazily).

Every function takes plain data, writes one PNG (100 dpi by default) and returns its path.
Figures are built with :class:`matplotlib.figure.Figure` and the Agg canvas directly, so no
pyplot global state and no display is touched.

Series are dicts ``{"label": str, "x": array, "y": array}`` with optional ``"reference": True``
(drawn black dashed: e.g. scikit-fem on the same meshes), ``"fit": RateFit`` (its slope goes into
the legend and the fitted line is drawn dotted) and ``"style"`` (matplotlib line keywords, usually
from a :class:`StyleBook`, so the same method looks the same in every figure of a report).
Points with non-finite or non-positive values are dropped from log axes, never plotted as garbage.
"""

from __future__ import annotations

import os
from typing import Iterable, Sequence

import numpy as np

from ..io.figures import new_figure, save_figure

__all__ = ["StyleBook", "REFERENCE_STYLE", "loglog_figure", "work_precision_figure", "energy_figure",
           "stability_map_figure"]

DPI = 100
#: 12 colours that stay distinguishable side by side (tab10 without its grey, plus navy, olive, teal).
PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#bcbd22", "#000080", "#6b6b00", "#008080")
_MARKERS = "osD^v<>phP*X"
#: the peer reference line (scikit-fem): black, dashed, crosses.
REFERENCE_STYLE = {"color": "k", "linestyle": "--", "marker": "x", "markersize": 7, "linewidth": 1.6,
                   "zorder": 1.9}


def _readable_log_ticks(ax) -> None:
    """Plain numbers (``0.01``, ``30``) instead of ``3x10^1``; no crowded minor labels on wide ranges."""
    from matplotlib.ticker import FuncFormatter, NullFormatter

    def fmt(v, _pos=None):
        if v <= 0:
            return ""
        return f"{v:g}" if 1e-3 <= v < 1e5 else f"$10^{{{int(round(np.log10(v)))}}}$" \
            if abs(np.log10(v) - round(np.log10(v))) < 1e-9 else f"{v:.0e}"

    from matplotlib.ticker import LogLocator

    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log":
            continue
        lo, hi = sorted((lo, hi))
        if lo > 0 and np.log10(hi / lo) < 2.5:  # short range: label 1, 2, 5 x 10^k
            axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(FuncFormatter(fmt))
        axis.set_minor_formatter(NullFormatter())


class StyleBook:
    """Colour + marker per method, line style per family, the same in every figure of a report.

    The first key asked for gets the first colour and marker, the next one the next; with at
    most ``len(PALETTE)`` (12) keys no two methods share a colour or a marker.

    >>> book = StyleBook({"explicit": "-", "symplectic": "--"})
    >>> a = book("explicit_euler", "explicit"); b = book("symplectic_euler", "symplectic")
    >>> a["color"] != b["color"], a["marker"] != b["marker"], b["linestyle"]
    (True, True, '--')
    >>> book("explicit_euler", "explicit") == a
    True
    """

    def __init__(self, linestyles: dict | None = None):
        self.linestyles = dict(linestyles or {})
        self._index: dict = {}

    def __call__(self, key, family=None, **extra) -> dict:
        i = self._index.setdefault(key, len(self._index))
        st = {"color": PALETTE[i % len(PALETTE)], "marker": _MARKERS[i % len(_MARKERS)],
              "linestyle": self.linestyles.get(family, "-"), "markersize": 5, "linewidth": 1.6}
        st.update(extra)
        return st


def _figure(width: float = 7.0, height: float = 5.0):
    return new_figure(width, height, dpi=DPI, layout="constrained")


def _save(fig, path) -> str:
    return os.fspath(save_figure(fig, path, dpi=DPI))


def _positive(x, y):
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    return x[ok], y[ok]


def _style(i: int, s: dict) -> dict:
    if s.get("style"):
        return {"markersize": 5, "linewidth": 1.6, **s["style"]}
    if s.get("reference"):
        return dict(REFERENCE_STYLE)
    return dict(color=PALETTE[i % len(PALETTE)], linestyle="-", marker=_MARKERS[i % len(_MARKERS)],
                markersize=5, linewidth=1.6)


def _legend(ax, n: int, title: str | None = None, outside: bool = False) -> None:
    """Inside the axes for a few lines; outside on the right for many (never over the data)."""
    kw = {"fontsize": 8, "title": title, "title_fontsize": 8}
    if n > 6 or outside:
        ax.figure.set_size_inches(10.0, 5.0)  # room for the legend beside the axes
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), **kw)
    else:
        ax.legend(**kw)


def _slope_triangle(ax, xs: np.ndarray, ys: np.ndarray, order: float, *, decreasing_x: bool) -> None:
    """Reference triangle of slope ``order`` under the data, spanning a third of the x range (log)."""
    lx0, lx1 = np.log10(xs.min()), np.log10(xs.max())
    if lx1 - lx0 <= 0:
        return
    width = (lx1 - lx0) / 3.0
    xa = 10 ** (lx0 + (lx1 - lx0) * 0.55)
    xb = xa * 10 ** width
    near = (xs >= xa / 1.5) & (xs <= xb * 1.5)
    low = ys[near].min() if near.any() else ys.min()
    # just under the lowest data in its x span, never over a line (slope p: the data rises as fast)
    ya = 0.4 * low * max(1.0, (xa / xb) ** order)
    yb = ya * (xb / xa) ** order
    # the right angle sits at the bottom: under the rising end for p > 0, under the falling start for p < 0
    xc = xb if order > 0 else xa
    ybot, ytop = min(ya, yb), max(ya, yb)
    ax.plot([xa, xb, xc, xa], [ya, yb, ybot, ya], color="k", linewidth=1.0)
    ax.text(np.sqrt(xa * xb), ybot * 0.8, "1", ha="center", va="top", fontsize=9)
    # the order beside the vertical edge, outside the triangle (which side is "outside" on screen
    # depends on whether the x axis is inverted)
    ha = "left" if (order > 0) != decreasing_x else "right"
    ax.text(xc * (1.05 if order > 0 else 1 / 1.05), np.sqrt(ybot * ytop), f"{abs(order):g}", va="center",
            ha=ha, fontsize=9)


def loglog_figure(path, series: Sequence[dict], *, title: str, xlabel: str, ylabel: str,
                  triangle: float | None = None, invert_x: bool = False, note: str | None = None,
                  legend_title: str | None = None) -> str:
    """Log-log lines (e.g. error vs h, error vs dofs, iterations vs dofs).

    ``triangle`` draws a reference slope triangle; ``invert_x`` puts large x on the left
    (error vs h then reads left to right as "finer mesh").
    """
    fig = _figure()
    ax = fig.add_subplot()
    allx, ally = [], []
    for i, s in enumerate(series):
        x, y = _positive(s["x"], s["y"])
        if x.size == 0:
            continue
        order = np.argsort(x)
        label = s["label"]
        fit = s.get("fit")
        st = _style(i, s)
        if fit is not None:
            quality = "2 points" if not np.isfinite(fit.r2) else f"R² {fit.r2:.3f}"
            label += f"  (rate {fit.slope:.2f}, {quality})"
        ax.plot(x[order], y[order], label=label, **st)
        if fit is not None:
            ax.plot(x[order], fit.predict(x[order]), color=st["color"], linestyle=":", linewidth=1.0)
        allx.append(x)
        ally.append(y)
    ax.set_xscale("log")
    ax.set_yscale("log")
    if triangle is not None and allx:
        _slope_triangle(ax, np.concatenate(allx), np.concatenate(ally), triangle, decreasing_x=invert_x)
    if invert_x:
        ax.invert_xaxis()
    _readable_log_ticks(ax)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    if note:
        ax.text(0.01, 0.01, note, transform=ax.transAxes, fontsize=8, color="0.3", va="bottom")
    if allx:
        # with a slope triangle and fit lines the inside of the axes is full: legend beside them
        _legend(ax, len(allx), legend_title, outside=triangle is not None)
    return _save(fig, path)


def work_precision_figure(path, series: Sequence[dict], *, front: Iterable[tuple[float, float]] = (),
                          title: str, xlabel: str = "run time [s]", ylabel: str = "error",
                          legend_title: str | None = None) -> str:
    """Error against run time, one line per method; the Pareto front drawn as a thick band.

    Lower-left wins: a point on the front is not beaten by any other run on both counts.
    """
    fig = _figure()
    ax = fig.add_subplot()
    front = [(t, e) for t, e in front if np.isfinite(t) and np.isfinite(e) and t > 0 and e > 0]
    if front:
        ft, fe = np.array(sorted(front)).T
        ax.step(ft, fe, where="post", color="gold", linewidth=8, alpha=0.5, zorder=0,
                label="Pareto front (not beaten on time and error)")
        ax.scatter(ft, fe, s=150, facecolors="none", edgecolors="darkorange", linewidths=1.8, zorder=3)
    any_data = bool(front)
    for i, s in enumerate(series):
        x, y = _positive(s["x"], s["y"])
        if x.size == 0:
            continue
        any_data = True
        ax.plot(x, y, label=s["label"], **_style(i, s))  # in sweep order (coarse to fine)
    ax.set_xscale("log")
    ax.set_yscale("log")
    _readable_log_ticks(ax)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.text(0.99, 0.99, "better: lower left", transform=ax.transAxes, ha="right", va="top", fontsize=8, color="0.3")
    if any_data:
        _legend(ax, len(series) + 1, legend_title)
    return _save(fig, path)


def energy_figure(path, series: Sequence[dict], *, title: str, floor: float = 1e-16,
                  legend_title: str | None = None) -> str:
    """Relative energy error ``|E(t) - E(0)| / |E(0)|`` against time, one line per integrator."""
    fig = _figure()
    ax = fig.add_subplot()
    drawn = False
    for i, s in enumerate(series):
        t = np.asarray(s["x"], dtype=float)
        e = np.asarray(s["y"], dtype=float)
        ok = np.isfinite(t) & np.isfinite(e)
        if not ok.any():
            continue
        st = _style(i, s)
        every = max(1, int(ok.sum()) // 10)  # markers tell lines apart, staggered so coinciding lines show each
        st.update(markevery=((3 * i) % every, every), markersize=4)
        ax.plot(t[ok], np.maximum(e[ok], floor), label=s["label"], **st)
        drawn = True
    ax.set_yscale("log")
    ax.set_title(title)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("relative energy error |E(t) - E(0)| / |E(0)|")
    ax.grid(True, which="both", alpha=0.3)
    if drawn:
        _legend(ax, len(series), legend_title)
    return _save(fig, path)


def stability_map_figure(path, rows: Sequence[dict], *, title: str) -> str:
    """Survived / unstable runs per method against ``dt * omega_max``.

    ``rows``: dicts with ``method``, ``h_omega`` (dt * omega_max), ``stable`` (bool) and optional
    ``bound`` (the theoretical limit of the method, drawn as a black bar on its row).
    """
    methods = list(dict.fromkeys(r["method"] for r in rows))
    fig = _figure(7.0, max(2.5, 0.6 * len(methods) + 1.5))
    ax = fig.add_subplot()
    ypos = {m: i for i, m in enumerate(methods)}
    hw = np.array([r["h_omega"] for r in rows], dtype=float)
    ok = np.array([bool(r["stable"]) for r in rows])
    yy = np.array([ypos[r["method"]] for r in rows], dtype=float)
    if ok.any():
        ax.scatter(hw[ok], yy[ok], marker="o", color="tab:green", s=40, label="survived", zorder=3)
    if (~ok).any():
        ax.scatter(hw[~ok], yy[~ok], marker="x", color="tab:red", s=50, label="unstable", zorder=3)
    bounds = {}
    for r in rows:
        b = r.get("bound")
        if b is not None and np.isfinite(b):
            bounds[r["method"]] = float(b)
    for j, (m, b) in enumerate(bounds.items()):
        y = ypos[m]
        ax.plot([b, b], [y - 0.35, y + 0.35], color="k", linewidth=2.5,
                label="theoretical limit" if j == 0 else None, zorder=2)
    ax.set_xscale("log")
    from matplotlib.ticker import FixedLocator, FormatStrFormatter, NullLocator

    span = np.concatenate([hw[np.isfinite(hw) & (hw > 0)], list(bounds.values())])  # the limits get labels too
    ticks = [t for t in (0.01, 0.03, 0.1, 0.25, 0.5, 1.0, 2.0, 2.83, 4.0, 8.0, 16.0)
             if span.size and span.min() / 1.5 <= t <= span.max() * 1.5]
    if ticks:
        ax.xaxis.set_major_locator(FixedLocator(ticks))
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_locator(NullLocator())
    ax.set_yticks(range(len(methods)), methods)
    ax.set_ylim(-0.6, len(methods) - 0.4)
    ax.set_xlabel("dt * omega_max  (dimensionless step)")
    ax.set_title(title)
    ax.grid(True, axis="x", which="both", alpha=0.3)
    if rows:
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3)
    return _save(fig, path)


def panels_figure(path, panels: Sequence[dict], *, title: str, ylabel: str) -> str:
    """One log-log panel per stress case (its own parameter on its own x axis), methods styled alike.

    ``panels``: dicts with ``title``, ``xlabel`` and ``series`` (dicts with ``label`` = method,
    ``x``, ``y`` and optional ``ok``: a bool per point; failed points are drawn as open red-rimmed
    markers). Each method keeps one colour and marker in every panel; one legend for all.
    """
    book = StyleBook()
    ncol = min(3, max(1, len(panels)))
    nrow = -(-len(panels) // ncol)
    fig = _figure(3.6 * ncol + 1.8, 3.0 * nrow + 0.6)
    axes = fig.subplots(nrow, ncol, squeeze=False).ravel()
    handles: dict = {}
    any_failed = False
    for ax, p in zip(axes, panels):
        for s in p["series"]:
            x, y = np.asarray(s["x"], dtype=float), np.asarray(s["y"], dtype=float)
            ok = np.asarray(s.get("ok", [True] * x.size), dtype=bool)
            keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
            if not keep.any():
                continue
            st = book(s["label"])
            order = np.argsort(x[keep])
            (line,) = ax.plot(x[keep][order], y[keep][order], **st)
            handles.setdefault(s["label"], line)
            bad = keep & ~ok
            if bad.any():
                any_failed = True
                ax.plot(x[bad], y[bad], linestyle="none", marker="o", markersize=10, markerfacecolor="none",
                        markeredgecolor="tab:red", markeredgewidth=1.5, zorder=4)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(p["title"], fontsize=10)
        ax.set_xlabel(p["xlabel"], fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        _readable_log_ticks(ax)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    for ax in axes[::ncol]:
        ax.set_ylabel(ylabel, fontsize=9)
    labels = list(handles)
    if any_failed:
        from matplotlib.lines import Line2D

        handles["failed"] = Line2D([], [], linestyle="none", marker="o", markersize=10, markerfacecolor="none",
                                   markeredgecolor="tab:red", markeredgewidth=1.5)
        labels.append("not converged (ringed)")
    fig.legend(list(handles.values()), labels, loc="outside right center", fontsize=8)
    fig.suptitle(title)
    return _save(fig, path)
