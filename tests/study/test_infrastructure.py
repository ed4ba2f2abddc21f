"""Fit, Pareto front, timing, report rendering: the study infrastructure on known data."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest

from femkit.errors import InputError
from femkit.study.fit import fit_rate
from femkit.study.pareto import pareto_front
from femkit.study.report import Report, staged_output, write_csv, write_json
from femkit.study.timing import StageTimer, time_call

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("rate", [1.0, 2.0, 2 / 3], ids=["rate1", "rate2", "rate2/3"])
def test_fit_recovers_exact_power_law(rate):
    h = 0.5 ** np.arange(2, 7)
    fit = fit_rate(h, 0.7 * h**rate)
    assert fit.slope == pytest.approx(rate, abs=1e-12)
    assert fit.intercept == pytest.approx(np.log(0.7), abs=1e-12)
    assert fit.r2 == pytest.approx(1.0, abs=1e-12)
    assert fit.slope_stderr == pytest.approx(0.0, abs=1e-10)


def test_fit_quality_reflects_scatter():
    rng = np.random.default_rng(0)
    h = 0.5 ** np.arange(1, 9)
    noisy = h**2 * np.exp(rng.normal(0, 0.3, h.size))
    fit = fit_rate(h, noisy)
    assert 0.5 < fit.r2 < 1.0
    assert fit.slope_stderr > 0.01
    # the true slope lies within a few standard errors
    assert abs(fit.slope - 2.0) < 4 * fit.slope_stderr
    # the standard error matches numpy's covariance estimate of the slope
    _, cov = np.polyfit(np.log(h), np.log(noisy), 1, cov="unscaled")
    resid_var = np.sum((np.log(noisy) - np.polyval(np.polyfit(np.log(h), np.log(noisy), 1), np.log(h))) ** 2) / (h.size - 2)
    assert fit.slope_stderr == pytest.approx(np.sqrt(cov[0, 0] * resid_var), rel=1e-10)


@pytest.mark.parametrize("x, y", [([1.0], [1.0]), ([1.0, 2.0], [1.0, 0.0]), ([1.0, 1.0], [1.0, 2.0]),
                                  ([1.0, np.nan], [1.0, 2.0])], ids=["one-point", "zero", "same-x", "nan"])
def test_fit_rejects_bad_input(x, y):
    with pytest.raises(InputError):
        fit_rate(x, y)


def test_pareto_front_brute_force():
    rng = np.random.default_rng(1)
    t, e = rng.random(60), rng.random(60)
    t[5], e[5] = np.nan, 0.0  # non-finite never on the front
    front = set(pareto_front(t, e).tolist())
    for i in range(60):
        if not (np.isfinite(t[i]) and np.isfinite(e[i])):
            assert i not in front
            continue
        ok = np.isfinite(t) & np.isfinite(e)
        dominated = np.any(ok & (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i])))
        assert (i in front) == (not dominated)


def test_timers():
    timer = StageTimer()
    with timer("a"):
        pass
    with timer("a"):
        pass
    assert set(timer.times) == {"a"} and timer.total >= 0
    calls = []
    t = time_call(lambda: calls.append(1) or len(calls), repeats=3, warmup=2)
    assert len(calls) == 5 and t.value == 5 and t.min <= t.median


def test_report_renders_and_replaces_atomically(tmp_path):
    from femkit.study.figures import loglog_figure

    out = tmp_path / "rep"
    out.mkdir()  # an earlier report (it has results.json), with a file the new one won't write
    (out / "results.json").write_text("{}")
    (out / "stale.txt").write_text("old run")
    h = 0.5 ** np.arange(1, 5)
    with staged_output(out) as stage:
        loglog_figure(stage / "figures" / "err.png",
                            [{"label": "L2", "x": h, "y": h**2, "fit": fit_rate(h, h**2)}],
                            title="t", xlabel="h", ylabel="e", triangle=2, invert_x=True)
        r = Report("demo")
        r.table(["h", "err"], [[float(a), float(a**2)] for a in h])
        r.figure("figures/err.png", "error vs h")
        r.write(stage)
        write_csv(stage / "runs.csv", [{"h": 0.5, "ok": True}, {"h": 0.25, "x": np.nan}])
        write_json(stage / "results.json", {"a": np.float64(np.inf), "b": np.arange(2)})
        assert not (out / "report.md").exists()  # nothing visible before success
    assert not (out / "stale.txt").exists()
    png = (out / "figures" / "err.png").read_bytes()
    assert png.startswith(PNG_SIGNATURE) and len(png) > 5000
    html = (out / "report.html").read_text()
    uris = re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", html)
    assert len(uris) == 1 and base64.b64decode(uris[0]) == png
    assert "![error vs h](figures/err.png)" in (out / "report.md").read_text()
    assert json.loads((out / "results.json").read_text()) == {"a": None, "b": [0, 1]}
    assert (out / "runs.csv").read_text().splitlines()[0] == "h,ok,x"


def test_failed_study_leaves_previous_report(tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "report.md").write_text("previous")
    with pytest.raises(RuntimeError):
        with staged_output(out) as stage:
            (stage / "report.md").write_text("half")
            raise RuntimeError("boom")
    assert (out / "report.md").read_text() == "previous"
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]
