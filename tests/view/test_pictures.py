"""Every kind's picture rendered off screen and judged by its pixels; ``femkit view`` writes
valid files (PNG, GIF, MP4; a Poisson run directory's indicators ``eta``); the notebook's frame
slider shows the frame it points at; the refusals (no pyvista, no off-screen OpenGL, no
imageio-ffmpeg for an MP4, a bad field) are one line, exit 2, nothing written.

One small run per kind and shape (module-scoped): Poisson 2D (in memory, with its estimator's
indicators) and 3D (the adaptive Fichera corner, from its run directory), a 2D scene with its
ground (soft disk), a 2D rope, a 3D cloth, a 3D solid; and a kind without a view of its own
(the generic PVD path). Pictures are 400 x 300: the pixel checks do not need more.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvista", reason="femkit[view] (pyvista) is part of the test extra")

from femkit.case import load_case  # noqa: E402
from femkit.cli import main  # noqa: E402
from femkit.view import open_view  # noqa: E402
from femkit.view.core import render  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SIZE = (400, 300)

#: name -> (case file, overrides): the cheapest run of each kind and shape.
RUNS = {
    "poisson2d": ("cases/poisson_lshape_adaptive.yaml", {"adaptive__max_dofs": 400}),
    "poisson3d": ("cases/fichera.yaml", {"adaptive__max_dofs": 600}),
    "disk": ("cases/scenes/soft_disk.yaml", {"t_end": 0.3, "output__interval": 0.1}),
    "rope": ("cases/scenes/rope_pendulum.yaml", {"t_end": 0.2}),
    "cloth": ("cases/scenes/hanging_cloth.yaml", {"t_end": 0.2, "output__frames": 4}),
    "solid": ("cases/solid_cantilever.yaml", {"mesh__h": 0.5, "static__load_steps": 2,
                                              "output__png": False, "output__gif": False}),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """name -> the result object of its run (written to a run directory)."""
    base = tmp_path_factory.mktemp("runs")
    out = {}
    for name, (path, overrides) in RUNS.items():
        case = load_case(ROOT / path, **overrides)
        out[name] = case.run(output_dir=base / name, quiet=True)
    return out


def judge(img: np.ndarray) -> dict:
    """What the pixel checks measure: the grey-level spread, the fraction of the drawing area
    (left of the colour bar) the body covers, and the count of distinct colours in the colour
    bar's strip."""
    h, w, _ = img.shape
    grey = img.astype(float).mean(axis=2)
    area = img[int(0.12 * h):int(0.92 * h), :int(0.8 * w)]
    covered = float(np.mean(np.any(area < 245, axis=2)))
    strip = img[int(0.25 * h):int(0.8 * h), int(0.85 * w):int(0.88 * w)].reshape(-1, 3)
    return {"std": float(grey.std()), "covered": covered,
            "bar_colours": len({tuple(c) for c in strip if min(c) < 245})}


def assert_picture(img: np.ndarray, min_cover: float = 0.03) -> None:
    j = judge(img)
    assert img.shape == (SIZE[1], SIZE[0], 3)
    assert j["std"] > 15, j                   # not blank
    assert min_cover < j["covered"] < 0.95, j  # the body covers a sensible part
    assert j["bar_colours"] >= 15, j           # the colour bar is there, a gradient


CASES = [("poisson2d", {}), ("poisson2d", {"field": "eta"}), ("poisson3d", {}),
         ("poisson3d", {"section": "slice"}), ("disk", {}), ("rope", {}), ("cloth", {}),
         ("cloth", {"field": "stretch"}), ("solid", {})]


@pytest.mark.parametrize("name, options", CASES, ids=[f"{n}-{o}" for n, o in CASES])
def test_every_kind_renders_a_picture_with_a_body_and_a_colour_bar(runs, name, options):
    result = runs[name]
    view = result.plot(size=SIZE, **options) if name == "poisson2d" else \
        open_view(result.output_dir, size=SIZE, **options)
    assert_picture(view.image(), min_cover=0.005 if name == "rope" else 0.03)


def test_a_scene_draws_its_obstacles_from_the_run_directory_and_from_the_result(runs):
    """The soft disk's ground (y = 0) is a layer of every frame, read from the case file for a
    run directory and from the forces of the result in memory."""
    for source in (runs["disk"].output_dir, runs["disk"]):
        picture = open_view(source).picture
        ground = [layer for layer in picture.frames[-1].layers if layer.color == "dimgrey"]
        assert len(ground) == 1
        assert np.allclose(np.asarray(ground[0].mesh.points)[:, 1], 0.0)


def test_the_checks_fail_on_a_picture_without_colours_or_without_a_body(runs):
    view = open_view(runs["poisson3d"].output_dir, size=SIZE)
    for layer in view.picture.frames[0].layers:
        layer.scalars = None  # one grey colour: no colour bar
    assert judge(view.image())["bar_colours"] < 15
    for layer in view.picture.frames[0].layers:
        layer.opacity = 0.0
    assert judge(view.image())["covered"] < 0.03


def test_the_3d_clip_shows_the_fichera_corner_singularity(runs):
    """u = r^(1/4) is smallest at the re-entrant vertex (0, 0, 0), which lies on the clip plane
    in the middle of the picture: the pixels of the lowest values (read back through viridis)
    gather around the image centre, and the colours span most of the colour map."""
    from matplotlib import colormaps

    img = open_view(runs["poisson3d"].output_dir, size=SIZE, edges=False).image().astype(float)
    top = int(0.12 * SIZE[1])
    area = img[top:, :int(0.8 * SIZE[0])]  # below the title, left of the colour bar
    area = area[::2, ::2]  # every other pixel: enough, and 4x cheaper
    lut = colormaps["viridis"](np.linspace(0, 1, 64))[:, :3] * 255
    dist = np.linalg.norm(area[:, :, None, :] - lut[None, None], axis=3)
    t, near = dist.argmin(axis=2), dist.min(axis=2) < 40
    assert near.mean() > 0.05 and np.ptp(t[near]) > 40
    low = np.argwhere(near & (t <= np.percentile(t[near], 1)))
    cy, cx = 2 * low.mean(axis=0) + (top, 0)
    assert abs(cy - SIZE[1] / 2) < 0.1 * SIZE[1] and abs(cx - SIZE[0] / 2) < 0.1 * SIZE[0], (cy, cx)


def test_a_kind_without_a_view_is_drawn_from_its_pvd(runs, tmp_path):
    run = tmp_path / "heat_run"
    shutil.copytree(runs["solid"].output_dir, run)
    meta = json.loads((run / "result.json").read_text())
    (run / "result.json").write_text(json.dumps(dict(meta, problem="not_a_kind_here")))
    view = open_view(run, size=SIZE, field="von_mises")
    assert len(view.picture.frames) == 3 and view.picture.fields[0] == "displacement"
    assert_picture(view.image())


@pytest.mark.parametrize("name", ["poisson3d", "cloth"])
def test_femkit_view_writes_a_png_and_a_gif(runs, name, tmp_path, capsys):
    png, gif = tmp_path / "a.png", tmp_path / "a.gif"
    code = main(["view", str(runs[name].output_dir), "--screenshot", str(png), "--movie", str(gif),
                 "--size", "400x300"])
    assert code == 0, capsys.readouterr().err
    from PIL import Image

    assert_picture(np.asarray(Image.open(png).convert("RGB")))
    import imageio.v2 as imageio

    frames = imageio.mimread(gif)
    n = len(open_view(runs[name].output_dir).picture.frames)
    assert len(frames) == n and frames[0].shape[:2] == (300, 400)
    if n > 1:
        assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 0
    assert judge(np.asarray(frames[-1])[..., :3])["bar_colours"] >= 15  # every frame has its bar
    assert not list(tmp_path.glob(".*"))  # no temporary file left


def _refused(capsys, argv, *words) -> str:
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert all(w in err for w in words), err
    return err


def test_a_bad_field_is_one_line_naming_the_valid_ones_nothing_written(runs, tmp_path, capsys):
    png = tmp_path / "x.png"
    _refused(capsys, ["view", str(runs["cloth"].output_dir), "--field", "nope", "--screenshot",
                      str(png)], "'nope'", "speed", "stretch")
    _refused(capsys, ["view", str(runs["solid"].output_dir), "--movie", str(tmp_path / "x.avi")],
             ".gif")
    _refused(capsys, ["view", str(tmp_path), "--screenshot", str(png)], "result.json")
    _refused(capsys, ["view", str(runs["solid"].output_dir), "--size", "big"], "WIDTHxHEIGHT")
    assert not list(tmp_path.iterdir())


def test_without_a_display_and_without_files_asked_the_picture_is_written_here(runs, tmp_path,
                                                                              monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.chdir(tmp_path)
    assert main(["view", str(runs["solid"].output_dir), "--field", "J", "--size", "400x300"]) == 0
    assert capsys.readouterr().out.strip() == "wrote solid_cantilever-J.png"
    from PIL import Image

    assert_picture(np.asarray(Image.open(tmp_path / "solid_cantilever-J.png").convert("RGB")))


def test_without_pyvista_one_line_names_the_extra(runs, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyvista", None)  # import pyvista -> ImportError
    png = tmp_path / "x.png"
    _refused(capsys, ["view", str(runs["poisson3d"].output_dir), "--screenshot", str(png)],
             "pip install femkit[view]")
    assert not png.exists()


def test_without_display_or_offscreen_opengl_one_line_names_what_to_install(runs, tmp_path,
                                                                            capsys, monkeypatch):
    monkeypatch.setattr(render, "offscreen_available", lambda: False)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    png = tmp_path / "x.png"
    _refused(capsys, ["view", str(runs["poisson3d"].output_dir), "--screenshot", str(png)],
             "libegl1", "scripts/install-view.sh")
    assert not png.exists()


STUDY_3D = ["study", str(ROOT / "studies" / "poisson_convergence_3d.yaml"), "--quick", "--set",
            "levels.count=2", "--set", "quadrature=[barycentric]", "--set",
            "solvers=[{method: direct}]", "--set", "reference=none", "--quiet"]


def test_a_3d_study_report_embeds_the_solution_and_works_without_pyvista(tmp_path, monkeypatch,
                                                                          capsys):
    assert main(STUDY_3D + ["--output", str(tmp_path / "with")]) == 0, capsys.readouterr().err
    from PIL import Image

    png = tmp_path / "with" / "figures" / "solution_3d.png"
    img = np.asarray(Image.open(png).convert("RGB").resize(SIZE))
    assert judge(img)["std"] > 15 and judge(img)["bar_colours"] >= 15
    assert "The discrete solution u on" in (tmp_path / "with" / "report.html").read_text()
    monkeypatch.setitem(sys.modules, "pyvista", None)
    assert main(STUDY_3D + ["--output", str(tmp_path / "without")]) == 0, capsys.readouterr().err
    html = (tmp_path / "without" / "report.html").read_text()
    assert "pip install femkit[view]" in html and "The discrete solution u on" not in html
    assert (tmp_path / "without" / "figures" / "error_vs_h.png").is_file()


#: Every bundled case and scene file with FEMKIT_VIEW_ALL=1 (.ci/run runs it as a step of its
#: own after the suite: about a minute on 2 cores with the kernels compiled); the default run
#: draws two cheap ones this way, beside the runs of every kind above.
BUNDLED = sorted((ROOT / "cases").glob("*.yaml")) + \
    sorted((ROOT / "cases" / "scenes").glob("*.yaml"))
if os.environ.get("FEMKIT_VIEW_ALL") != "1":
    BUNDLED = [p for p in BUNDLED if p.stem in ("poisson_unit_square", "stiff_spring_implicit")]


def _small(path: Path) -> dict:
    """Overrides that make a bundled file's run short, by its kind: a coarser mesh, fewer
    adaptive levels, steps or load steps; what is drawn is still the file's own problem."""
    import yaml

    data = yaml.safe_load(path.read_text())
    mesh = data.get("mesh", {})
    small = {"mesh__refine": 1} if mesh.get("refine", 0) > 1 else {}  # fmg needs one level
    if data["problem"] == "poisson":
        if data.get("adaptive"):
            small["adaptive__max_dofs"] = 500
        return dict(small, output__vtu=True, output__plot=False)
    if data["problem"] == "mass_spring":
        system = data.get("system", {})
        if system.get("nx", 0) > 21:  # a large cloth: 21 x 21 nodes show it as well
            small.update(system__nx=21, system__ny=21)
        return dict(small, t_end=0.05, output__png=False)
    if "h" in mesh:
        small["mesh__h"] = 2 * mesh["h"]
    if "static" in data:
        return dict(small, static__load_steps=2, output__png=False, output__gif=False)
    return dict(small, t_end=0.02, output__png=False, output__gif=False)


@pytest.mark.parametrize("path", BUNDLED, ids=[p.stem for p in BUNDLED])
def test_a_bundled_file_renders(path, tmp_path):
    load_case(path, **_small(path)).run(output_dir=tmp_path / "run", quiet=True)
    img = open_view(tmp_path / "run", size=SIZE).image()
    j = judge(img)
    assert j["std"] > 15 and j["bar_colours"] >= 15 and 0.005 < j["covered"] < 0.95, j


#: Every bundled study with FEMKIT_VIEW_ALL=1 (the same .ci/run step), each at its ``quick:``
#: block; the default run draws the cheapest (about 1.5 s).
STUDIES = sorted((ROOT / "studies").glob("*.yaml"))
if os.environ.get("FEMKIT_VIEW_ALL") != "1":
    STUDIES = [p for p in STUDIES if p.stem == "element_work_precision"]
#: study -> further --set overrides where its quick: block alone is over ~20 s on 2 cores: the
#: stiff heat study's finer quick mesh (h = 1/128, 32 runs: 23 s) is swapped for h = 1/64.
SHRINK = {"heat_work_precision_stiff": ["--set", "quick.h=[0.03125, 0.015625]"]}


def assert_figure(img: np.ndarray) -> None:
    """A study's picture: not blank, the figure covering a sensible part, the plot's coloured
    lines and markers there (a matplotlib figure on white; a blank or grey image has none)."""
    j = judge(img)
    coloured = np.ptp(img.astype(int), axis=2) > 80  # saturated pixels: the curves
    assert img.shape == (SIZE[1], SIZE[0], 3)
    assert j["std"] > 15 and 0.03 < j["covered"] < 0.95, j
    assert coloured.sum() >= 40, int(coloured.sum())
    assert (img[:int(0.08 * SIZE[1])] < 100).any()  # the title


@pytest.mark.parametrize("path", STUDIES, ids=[p.stem for p in STUDIES])
def test_a_bundled_study_renders(path, tmp_path, capsys):
    out, png = tmp_path / "study", tmp_path / "study.png"
    argv = ["study", str(path), "--quick", "--quiet", "--output", str(out)]
    assert main(argv + SHRINK.get(path.stem, [])) == 0, capsys.readouterr().err
    code = main(["view", str(out), "--screenshot", str(png), "--size", "400x300"])
    assert code == 0, capsys.readouterr().err
    from PIL import Image

    assert_figure(np.asarray(Image.open(png).convert("RGB")))
    first = json.loads((out / "results.json").read_text())["figures"][0]
    assert open_view(out).picture.field == Path(first).stem  # the report's first figure


def test_a_study_view_picks_its_figures_and_refuses_a_bad_one_or_a_bad_directory(tmp_path,
                                                                                 capsys):
    """``femkit view`` and ``StudyResult.plot`` draw the figure named, each its own picture."""
    out = tmp_path / "study"
    argv = ["study", str(ROOT / "studies" / "element_work_precision.yaml"), "--quick", "--quiet",
            "--output", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    figures = [Path(f).stem for f in json.loads((out / "results.json").read_text())["figures"]]
    from femkit.study import StudyResult

    result = StudyResult(kind="element_work_precision", name="ewp", records=[], output_dir=out)
    views = [result.plot(field=f, size=SIZE) for f in figures[:2]]
    assert [v.fields for v in views] == [tuple(figures)] * 2
    assert open_view(result).picture.field == figures[0]
    a, b = (v.image() for v in views)
    assert_figure(a), assert_figure(b)
    assert np.abs(a.astype(int) - b.astype(int)).mean() > 1  # two figures, two pictures
    png = tmp_path / "x.png"
    _refused(capsys, ["view", str(out), "--field", "nope", "--screenshot", str(png)], "'nope'",
             *figures)
    (out / "report.md").unlink()  # neither a run nor a study directory now
    _refused(capsys, ["view", str(out), "--screenshot", str(png)], "result.json", "results.json",
             "report.md")
    assert not png.exists()


def test_the_window_slider_redraws_the_chosen_frame(runs):
    """:func:`render.show`'s slider callback, on an off-screen plotter: frame 0 (the cloth at
    rest, every node still) and the last frame (falling) differ; the colour bar stays."""
    picture = open_view(runs["cloth"].output_dir).picture
    p = render.plotter(SIZE)
    try:
        render.draw(p, picture, -1)
        go = render.frame_slider(p, picture)
        images = []
        for k in (0, len(picture.frames) - 1):
            go(k)
            images.append(np.asarray(p.screenshot(None, return_img=True)))
    finally:
        p.close()
    assert np.abs(images[0].astype(int) - images[1].astype(int)).max() > 50
    assert all(judge(img)["bar_colours"] >= 15 for img in images)


@pytest.mark.parametrize("name", ["disk", "cloth"])
def test_the_notebook_slider_shows_the_frame_it_points_at(runs, name):
    """The ipywidgets slider (femkit.view.slider), built and moved without a browser: the image
    changes with the value, each frame is rendered once, and a 2D frame is pixel for pixel the
    frame's own picture (View.frame(k)); a 3D frame is drawn with the first frame's camera."""
    from PIL import Image

    from femkit.view import slider

    def pixels(png: bytes) -> np.ndarray:
        import io

        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))

    box = slider(runs[name].output_dir, size=SIZE)
    img, row = box.children
    bar, label = row.children
    n = len(box.frames)
    assert n > 2 and (bar.min, bar.max, bar.value) == (0, n - 1, n - 1)
    last = pixels(img.value)
    bar.value = 0
    first = pixels(img.value)
    assert np.abs(first.astype(int) - last.astype(int)).max() > 50, "the image did not change"
    assert label.value.startswith("t = ") and label.value != box.frames.label(n - 1)
    assert_picture(first, min_cover=0.005)
    view = open_view(runs[name].output_dir, size=SIZE)
    if name == "disk":
        np.testing.assert_array_equal(first, view.frame(0).image())
    else:
        camera = render.series_camera(view.picture, SIZE)
        np.testing.assert_array_equal(first, render.image(view.picture, 0, SIZE, camera=camera))
    bar.value = n - 1
    assert np.array_equal(pixels(img.value), last) and box.frames.rendered == 2  # kept, not redrawn


def test_an_mp4_is_written_and_read_back_frame_by_frame(runs, tmp_path, capsys):
    pytest.importorskip("imageio_ffmpeg", reason="femkit[view] installs imageio-ffmpeg")
    import imageio.v2 as imageio

    mp4 = tmp_path / "cloth.mp4"
    code = main(["view", str(runs["cloth"].output_dir), "--movie", str(mp4), "--size", "400x300"])
    assert code == 0, capsys.readouterr().err
    reader = imageio.get_reader(mp4)
    frames = [np.asarray(f) for f in reader]
    reader.close()
    assert len(frames) == len(open_view(runs["cloth"].output_dir).picture.frames)
    assert frames[0].shape == (300, 400, 3)  # as drawn: not resized
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 50
    assert judge(frames[-1])["bar_colours"] >= 15
    assert not list(tmp_path.glob(".*"))


def test_without_imageio_ffmpeg_an_mp4_is_one_line_naming_it(runs, tmp_path, capsys, monkeypatch):
    import importlib.util

    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "imageio_ffmpeg" else find_spec(name, *a))
    _refused(capsys, ["view", str(runs["solid"].output_dir), "--movie", str(tmp_path / "x.mp4")],
             "pip install imageio-ffmpeg", ".gif")
    assert not list(tmp_path.iterdir())


def test_a_poisson_run_directory_draws_its_indicators(runs, tmp_path, capsys):
    """solution.vtu holds eta: `femkit view RUN --field eta` draws it (log scale) from the
    file, the values those of the run; an unknown field lists the valid ones."""
    run = runs["poisson2d"].output_dir
    png = tmp_path / "eta.png"
    code = main(["view", str(run), "--field", "eta", "--screenshot", str(png), "--size", "400x300"])
    assert code == 0, capsys.readouterr().err
    from PIL import Image

    assert_picture(np.asarray(Image.open(png).convert("RGB")))
    picture = open_view(run, field="eta").picture
    layer = picture.frames[0].layers[0]
    assert layer.log and picture.field == "eta"
    np.testing.assert_array_equal(np.asarray(layer.mesh.cell_data["eta"]), runs["poisson2d"].indicators)
    _refused(capsys, ["view", str(run), "--field", "nope", "--screenshot", str(tmp_path / "x.png")],
             "'nope'", "eta", "kappa", "tag", "u")
    assert not (tmp_path / "x.png").exists()
