"""Progress lines without a terminal: one per 10 % or per minute, with elapsed and remaining time,
at least ``min_interval`` apart (a short run prints its last line only), the remaining time
scaled by the predicted cost of the work left."""

import io

from femkit.progress import Progress, progress


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_ten_lines_for_a_full_run_with_remaining_time():
    clock = FakeClock()
    out = io.StringIO()
    bar = Progress(2000, "scene cloth", mode="lines", stream=out, clock=clock, min_interval=0)
    for _ in range(2000):
        clock.t += 0.01  # 0.01 s per step: 20 s in all
        bar.update()
    bar.close()
    lines = out.getvalue().splitlines()
    assert len(lines) == 10
    assert lines[0] == "scene cloth: 10% (200/2000 steps), elapsed 2 s, remaining ~18 s"
    assert lines[-1] == "scene cloth: 100% (2000/2000 steps), elapsed 20 s"


def test_a_line_per_minute_when_ten_percent_takes_longer():
    clock = FakeClock()
    out = io.StringIO()
    bar = Progress(100_000, "slow", mode="lines", stream=out, clock=clock)
    for _ in range(2000):  # 2 % of the work in 3.3 min: three minute marks, no 10 % mark
        clock.t += 0.1
        bar.update()
    lines = out.getvalue().splitlines()
    assert len(lines) == 3
    assert lines[0] == "slow: 1% (600/100000 steps), elapsed 1 min, remaining ~2.8 h"


def test_quiet_prints_nothing_and_interruption_is_reported():
    out = io.StringIO()
    bar = Progress(10, "x", quiet=True, stream=out)
    bar.update(5)
    bar.close("SIGTERM")
    assert out.getvalue() == ""
    out = io.StringIO()
    bar = Progress(10, "x", mode="auto", stream=out)  # StringIO is not a terminal: lines
    assert bar.mode == "lines"
    bar.update(5)
    bar.close("SIGTERM")
    assert out.getvalue().splitlines()[-1].endswith("interrupted by SIGTERM")


def test_progress_iterator():
    out = io.StringIO()
    assert list(progress(range(20), desc="study", stream=out, mode="lines")) == list(range(20))
    assert out.getvalue().count("\n") == 1 and "100% (20/20 jobs)" in out.getvalue()


def test_a_short_run_prints_its_last_line_only_and_lines_stay_min_interval_apart():
    """Issue 17: a 0.06 s run printed 10 lines. 2000 steps of 0.01 s with lines >= 5 s apart:
    the 10 % marks at 6, 12 and 18 s, then the end."""
    clock = FakeClock()
    out = io.StringIO()
    bar = Progress(2000, "scene", mode="lines", stream=out, clock=clock)
    for _ in range(2000):
        clock.t += 0.01
        bar.update()
    assert [line.split(",")[1] for line in out.getvalue().splitlines()] == [
        " elapsed 6 s", " elapsed 12 s", " elapsed 18 s", " elapsed 20 s"]
    short = io.StringIO()
    clock.t = 0.0
    bar = Progress(10, "short", mode="lines", stream=short, clock=clock)
    for _ in range(10):
        clock.t += 0.006  # 0.06 s in all
        bar.update()
    assert short.getvalue().splitlines() == ["short: 100% (10/10 steps), elapsed 0.06 s"]


def test_remaining_time_follows_the_predicted_cost_not_the_first_runs():
    """Issue 17: '1.6 s remaining' before 11 minutes. Two cheap runs (cost 1 each, 1 s each)
    then one of cost 98: after the cheap ones ~98 s remain, not ~0.5 s."""
    clock = FakeClock()
    out = io.StringIO()
    bar = Progress(3, "study", unit="run", mode="lines", stream=out, clock=clock, cost=100.0,
                   min_interval=0)
    for cost in (1.0, 1.0):
        clock.t += 1.0
        bar.update(cost=cost)
    assert out.getvalue().splitlines()[-1] == "study: 67% (2/3 runs), elapsed 2 s, remaining ~1.6 min"
    uniform = Progress(3, "study", unit="run", mode="off", clock=clock)
    clock.t, uniform.start = 2.0, 0.0
    uniform.update(2)
    assert uniform.line().endswith("remaining ~1 s")  # without costs: by count


def test_progress_counts_sizes_and_reports_an_interruption():
    from femkit.interrupt import StopFlag

    out = io.StringIO()
    assert list(progress("abc", sizes=[2, 3, 1], desc="conv", unit="run", stream=out,
                         mode="lines")) == ["a", "b", "c"]
    assert len(out.getvalue().splitlines()) == 1
    assert out.getvalue().startswith("conv: 100% (6/6 runs)")
    import pytest

    from femkit.interrupt import Interrupted

    flag, out = StopFlag(), io.StringIO()

    with pytest.raises(Interrupted, match=r"before run 3 of 6 \(2 done\)"):
        for item in progress("abc", sizes=[2, 3, 1], unit="run", stream=out, mode="lines",
                             stop=flag):
            flag.request(2)
    last = out.getvalue().splitlines()[-1]
    assert ": 33% (2/6 runs), elapsed " in last
    assert last.endswith("; interrupted by SIGINT")


def test_progress_stops_before_the_next_item_on_request():
    """With ``stop=`` the item after a stop request is not started: Interrupted names it."""
    import pytest

    from femkit.interrupt import Interrupted, StopFlag

    flag, seen = StopFlag(), []
    with pytest.raises(Interrupted, match=r"by SIGTERM before run 3 of 5 \(2 done\)"):
        for i in progress(range(5), unit="run", enabled=False, stop=flag):
            seen.append(i)
            if i == 1:
                flag.request(15)
    assert seen == [0, 1]


def test_planned_stages_report_the_remaining_time_scaled_by_the_pace():
    """Stages predicted 5 s + 15 s; the first takes 10 s (twice slower): ~30 s remain."""
    clock = FakeClock()
    out = io.StringIO()
    bar = Progress.planned([("mesh", 5.0), ("refine", 1.0), ("solve", 15.0)], "case",
                           stream=out, min_seconds=0, clock=clock)
    clock.t = 12.0
    bar.done("mesh", "refine")  # mesh includes refine: 6 s predicted, 12 s taken
    clock.t = 40.0
    bar.done("solve")
    assert out.getvalue().splitlines() == ["case: mesh done, elapsed 12 s, remaining ~30 s",
                                           "case: solve done, elapsed 40 s"]
    quiet = io.StringIO()
    short = Progress.planned([("mesh", 5.0)], "case", stream=quiet)  # below 30 s: silent
    short.done("mesh")
    assert quiet.getvalue() == ""
