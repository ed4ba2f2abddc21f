"""Solid runs that fail, cut their load steps, warn, print their times and draw small motions
(issue 30): a failed run keeps its frames and verdict, a load step's prescribed increment is
spread into the body (and cut when it still inverts elements), warnings are femkit's one-line
ones, the summary has the stage times and the wall line, the bundled cases write to
``runs/<name>`` like the Poisson ones, and the pictures magnify a small deformation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

import femkit
from femkit.cli import main

REPO = Path(__file__).parents[2]

#: the issue's case: a 1.5 x 0.8 x 0.6 box on rollers, a log(J) energy, face xmax moved by -0.3
#: in two load steps. Moving only the held nodes inverted 62 elements of the next layer.
LOG_J = {
    "problem": "solid",
    "name": "log_j_box",
    "mesh": {"geometry": "box", "h": 0.2, "params": {"lx": 1.5, "ly": 0.8, "lz": 0.6}},
    "material": {"energy": {"W": "mu/2*(s1**2+s2**2+s3**2-3) - mu*log(J) + lam/2*log(J)**2"},
                 "constants": {"mu": 700, "lam": 1800}},
    "boundaries": [{"tag": "xmin", "type": "roller", "fix": ["x"]},
                   {"tag": "ymin", "type": "roller", "fix": ["y"]},
                   {"tag": "zmin", "type": "roller", "fix": ["z"]},
                   {"tag": "xmax", "type": "fixed", "fix": ["x"], "displacement": [-0.3, 0, 0]}],
    "static": {"load_steps": 2},
    "output": {"png": False},
}


#: most tests here run the log(J) energy: one worker runs them all, so it is compiled once (~40 s
#: on a cold cache), not once by each worker that meets it first
pytestmark = pytest.mark.xdist_group("log_j_energy")


def _write(tmp_path, data) -> Path:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _held_nodes_only(self, x, lf):
    """The increment applied to the held nodes alone (what load steps did before issue 30)."""
    out = x.copy()
    out[self.fixed] = self.X[self.fixed] + lf * self.u_fixed
    return out


def _solve(tmp_path, capsys, data=LOG_J):
    out = tmp_path / "out"
    code = main(["solve", str(_write(tmp_path, data)), "--output", str(out)])
    cap = capsys.readouterr()
    return code, out, cap


def test_log_j_compression_converges_from_the_spread_increment(tmp_path, capsys):
    code, out, cap = _solve(tmp_path, capsys)
    assert code == 0, cap.err
    d = json.loads((out / "result.json").read_text())
    assert d["verdict"] == "converged" and d["frames"] == 3
    assert [s["substeps"] for s in d["load_steps"]] == [1, 1]   # the spread start is admissible
    assert d["inverted_elements"] == 0
    # the rollers and the moved face: the box is 1.2 long now, its volume smaller
    assert d["tip_displacement"][0] == pytest.approx(-0.3)
    assert -0.3 < d["volume"]["final"] / d["volume"]["rest"] - 1 < 0.0
    assert "femkit: failed" not in cap.err


def test_an_increment_that_inverts_elements_is_cut_and_reported(tmp_path, capsys, monkeypatch):
    """With the increment on the held nodes alone, the first start has infinite energy: the
    step is cut until it is finite, converges to the same equilibrium, and says so."""
    from femkit.solids import static

    (tmp_path / "whole").mkdir()
    _, out, _ = _solve(tmp_path / "whole", capsys)
    whole = json.loads((out / "result.json").read_text())
    monkeypatch.setattr(static._Newton, "spread", _held_nodes_only)
    code, out, cap = _solve(tmp_path, capsys)
    assert code == 0, cap.err
    d = json.loads((out / "result.json").read_text())
    assert d["verdict"] == "converged"
    assert d["load_steps"][0]["substeps"] > 1
    assert "cut into sub-steps where the whole increment inverted elements: load step 1 in" in cap.out
    assert d["tip_displacement"] == pytest.approx(whole["tip_displacement"], abs=1e-8)


def test_a_failed_load_step_keeps_its_frames_and_verdict(tmp_path, capsys, monkeypatch):
    """No cut allowed: the failure the issue saw (exit 1, nothing written) now writes the rest
    frame, newton_failed and the failure, exit 1."""
    from femkit.solids import static

    monkeypatch.setattr(static._Newton, "spread", _held_nodes_only)
    monkeypatch.setattr(static, "MAX_CUTS", 0)
    code, out, cap = _solve(tmp_path, capsys)
    assert code == 1
    d = json.loads((out / "result.json").read_text())
    assert d["verdict"] == "newton_failed" and d["converged"] is False
    assert d["frames"] == 1 and (out / "frames" / "frame_00000.vtu").is_file()
    assert "load step 1/2" in d["failure"] and "inverts elements" in d["failure"]
    assert "femkit: newton failed: load step 1/2" in cap.err
    assert "Traceback" not in cap.err


def test_a_linear_solve_failure_in_a_load_step_keeps_the_frames(tmp_path, capsys, monkeypatch):
    from femkit.errors import SolverError
    from femkit.solids import static

    calls = []

    def fail_second(self, x, f, rec):
        calls.append(1)
        if len(calls) == 2:
            raise SolverError("the linear solve missed its residual rule")
        return real(self, x, f, rec)

    real = static._Newton.newton
    monkeypatch.setattr(static._Newton, "newton", fail_second)
    code, out, cap = _solve(tmp_path, capsys)
    assert code == 1
    d = json.loads((out / "result.json").read_text())
    assert d["verdict"] == "solver_failed" and d["frames"] == 2
    assert "load step 2/2" in d["failure"]


def test_summary_has_stage_times_and_the_wall_line(tmp_path, capsys):
    code, out, cap = _solve(tmp_path, capsys)
    assert code == 0
    lines = cap.out.splitlines()
    time_line = next(line for line in lines if line.startswith("time "))
    for stage in ("build", "solve", "output"):
        assert f"{stage} " in time_line
    assert lines[-1].startswith("wall ") and "start-up and imports" in lines[-1]
    assert any(line.startswith("steps     2 of 2 load steps") for line in lines)


def test_warnings_are_one_femkit_line_each(tmp_path, capsys):
    """An implicit step whose Newton stops at its iteration limit warns: one line, femkit's."""
    data = {**LOG_J, "static": None, "output": {"png": False, "vtu": False},
            "material": {"model": "stable_neo_hookean", "E": 1000.0, "nu": 0.3},
            "integrator": {"method": "newton", "options": {"max_iterations": 1}},
            "dt": 0.01, "t_end": 0.03,
            "boundaries": LOG_J["boundaries"][:3] + [
                {"tag": "xmax", "type": "traction", "traction": [-300.0, 0, 0]}]}
    data.pop("static")
    code, out, cap = _solve(tmp_path, capsys, data)
    warned = [line for line in cap.err.splitlines() if "warning" in line.lower()]
    assert warned, cap.err
    assert all(line.startswith("femkit: warning: ") for line in warned), warned
    assert ".py:" not in cap.err
    d = json.loads((out / "result.json").read_text())
    assert d["warnings"] and all("\n" not in w for w in d["warnings"])


def test_cli_prints_a_foreign_warning_on_one_line(capsys):
    import warnings

    from femkit.cli.messages import one_line_warning

    one_line_warning(RuntimeWarning("overflow encountered\n in multiply"), RuntimeWarning,
                     "/x/y.py", 3)
    one_line_warning(UserWarning("plain"), UserWarning, "/x/y.py", 3)
    assert capsys.readouterr().err.splitlines() == [
        "femkit: warning: overflow encountered in multiply (RuntimeWarning)",
        "femkit: warning: plain"]
    assert warnings.showwarning is not one_line_warning   # main() restores Python's own


@pytest.mark.parametrize("path", sorted([*(REPO / "cases").glob("*.yaml"),
                                          *(REPO / "cases" / "scenes").glob("*.yaml")]),
                         ids=lambda p: p.stem)
def test_bundled_cases_write_to_runs_at_the_repository_root(path):
    case = femkit.load_case(path)
    assert Path(case.spec.output.dir).parent == REPO / "runs", case.spec.output.dir


@pytest.mark.parametrize("u_max, size, scale", [(0.013, 2.0, 20.0), (0.04332, 2.0, 5.0),
                                                 (0.3, 2.0, 1.0), (0.5, 2.0, 1.0),
                                                 (1e-7, 1.0, 1e6), (0.0, 1.0, 1.0)])
def test_display_scale_is_round_and_shows_at_most_the_fraction(u_max, size, scale):
    from femkit.case.solid.plot import SHOWN_FRACTION, display_scale

    s = display_scale(u_max, size)
    assert s == pytest.approx(scale)
    if s > 1:
        assert s * u_max <= SHOWN_FRACTION * size * (1 + 1e-12)
        assert 2.5 * s * u_max > SHOWN_FRACTION * size   # the next round number would overshoot


def test_beam_picture_is_magnified_framed_and_its_colour_bar_clear(tmp_path):
    """The vibrating beam's first sag (~0.02 on 2 m) drawn magnified, the factor in the title;
    the colour bar overlaps no axis label and no tick label."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from femkit.case.solid.plot import display_scale, plot_solid_frame

    case = femkit.load_case(REPO / "cases" / "solid_beam_vibration.yaml", t_end=0.05)
    result = case.run(write=False, quiet=True)
    fig = plot_solid_frame(result)
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    u_max = float(np.linalg.norm(result.x[-1] - result.problem.body.rest_positions, axis=1).max())
    factor = display_scale(u_max, 2.0)
    assert factor >= 5 and f"displacement x {factor:g} " in fig._suptitle.get_text()
    body_ax, bar_ax = fig.axes
    bar = bar_ax.get_window_extent(renderer)
    labels = [t for axis in (body_ax.xaxis, body_ax.yaxis, body_ax.zaxis)
              for t in axis.get_ticklabels() + [axis.label] if t.get_visible() and t.get_text()]
    assert labels
    assert not any(t.get_window_extent(renderer).overlaps(bar) for t in labels)
    # the frame holds the magnified sag, well below where the true one would end
    rest_z = result.problem.body.rest_positions[:, 2]
    u_z = result.x[-1][:, 2] - rest_z
    lo = body_ax.get_zlim()[0]
    assert lo < (rest_z + factor * u_z).min()
    assert lo < (rest_z + u_z).min() + 0.5 * (factor - 1) * u_z.min()


def test_a_stop_between_load_steps_keeps_them_marked_without_pictures(tmp_path, monkeypatch):
    """A stop request (the flag ``femkit solve`` sets on SIGINT) after the first of three load
    steps: that step's frame is written, marked interrupted, and no picture is drawn."""
    from femkit.case.solid import run as solid_run
    from femkit.interrupt import StopFlag

    flag = StopFlag()
    real = solid_run.frame_energies

    calls = []

    def energies_then_stop(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:          # the rest frame, then the first load step's: then Ctrl-C
            flag.request()
        return real(*args, **kwargs)

    monkeypatch.setattr(solid_run, "frame_energies", energies_then_stop)
    data = {**LOG_J, "static": {"load_steps": 3}, "output": {"png": True, "gif": True}}
    case = femkit.load_case(_write(tmp_path, data)).with_options(stop=flag)
    result = case.run(output_dir=tmp_path / "out", quiet=True)
    assert result.interrupted == "SIGINT" and not result.converged
    d = json.loads((tmp_path / "out" / "result.json").read_text())
    assert d["interrupted"] is True and d["verdict"] == "interrupted"
    assert d["steps"] == 1 and d["steps_planned"] == 3 and d["frames"] == 2
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "frames", "result.json", "solid.pvd"]
