"""Figures a person can read: tick labels that do not touch, text of at least 8 pt, GIF frames
large enough to read, a dense adaptive mesh shown as sizes rather than a grey moire."""

import inspect

import numpy as np
import pytest


def _overlaps(labels, renderer, axis: str) -> list:
    """Neighbouring tick labels closer than half a character (touching reads as one number)."""
    shown = [t for t in labels if t.get_visible() and t.get_text()]
    boxes = sorted((t.get_window_extent(renderer) for t in shown),
                   key=lambda b: b.x0 if axis == "x" else b.y0)
    if not shown:
        return []
    space = 0.5 * shown[0].get_fontsize() * renderer.points_to_pixels(1.0)
    gaps = [(b.x0 - a.x1) if axis == "x" else (b.y0 - a.y1) for a, b in zip(boxes, boxes[1:])]
    return [g for g in gaps if g < space]


@pytest.mark.parametrize("geometry, h", [("l_shape", 0.1), ("unit_square", 0.1), ("annulus", 0.15)])
def test_solution_png_tick_labels_do_not_touch(tmp_path, geometry, h):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    import femkit.case.poisson.output as output
    from femkit.mesh import generate

    mesh = generate(geometry, h=h)
    figures = []
    real = output.save_figure
    output.save_figure = lambda fig, path: figures.append(fig) or real(fig, path)
    try:
        output.write_plot(tmp_path / "s.png", mesh, mesh.points[:, 0], title="t",
                          indicators=np.random.default_rng(0).random(mesh.n_triangles), estimator="residual")
    finally:
        output.save_figure = real
    fig = figures[0]
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    for ax in fig.axes:
        assert _overlaps(ax.get_xticklabels(), renderer, "x") == []
        assert _overlaps(ax.get_yticklabels(), renderer, "y") == []


def test_scene_frame_text_is_at_least_8_points_and_gif_frames_are_readable():
    from femkit.case.scene import plot

    src = inspect.getsource(plot)
    sizes = [float(s) for s in __import__("re").findall(r"labelsize=(\d+(?:\.\d+)?)", src)]
    assert sizes and min(sizes) >= 8
    gif_dpi = inspect.signature(plot.write_gif).parameters["dpi"].default
    width, height = inspect.signature(plot.plot_frame).parameters["size"].default
    assert width * gif_dpi >= 900 and height * gif_dpi >= 450


def test_dense_adaptive_mesh_is_drawn_as_local_size(tmp_path):
    import femkit.study.adaptive.report as adaptive
    from femkit.mesh import generate

    figures = []
    import femkit.io.figures as figs

    real = figs.save_figure
    figs.save_figure = lambda fig, path: figures.append(fig) or real(fig, path)
    try:
        small = generate("l_shape", h=0.2)
        adaptive._mesh_figure(tmp_path / "a.png", small, np.ones(small.n_triangles), "few")
        old = adaptive._DRAWN_EDGES_MAX
        adaptive._DRAWN_EDGES_MAX = small.n_triangles - 1  # the same mesh counts as dense now
        try:
            adaptive._mesh_figure(tmp_path / "b.png", small, np.ones(small.n_triangles), "many")
        finally:
            adaptive._DRAWN_EDGES_MAX = old
    finally:
        figs.save_figure = real
    few, many = figures
    assert len(few.axes[0].lines) > 0        # the edges, drawn by triplot
    assert len(many.axes[0].lines) == 0      # too many: the size field instead
    assert len(many.axes[0].collections) == 1
    assert "size shown" in many.axes[0].get_title()
    for fig in (few, many):
        for ax in fig.axes[:3]:
            assert ax.get_xlabel() == "x" and ax.get_ylabel() == "y"
