"""The live time-left estimate is measured from the run's own progress after its start-up (issue 25).

A synthetic clock drives the reporters: no wall time is read or asserted.
"""

from __future__ import annotations

import io
import math
import re

import pytest

from weftsim.checks.progress import Progress, RateEstimate
from weftsim.sweep.pool import SweepProgress


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


LEFT = re.compile(r"(\d+(?:\.\d+)?)%.*elapsed\s+(\d+(?:\.\d+)?) s\s+left ~\s*(\d+(?:\.\d+)?) s")


def _run(progress_at, end: float, clock: Clock, reporter, dt: float = 0.01) -> None:
    """Call ``reporter(progress_at(t))`` every ``dt`` of synthetic time up to ``end``."""
    for k in range(int(round(end / dt)) + 1):
        clock.now = k * dt
        reporter(progress_at(clock.now))


def test_a_start_up_without_progress_does_not_inflate_the_time_left():
    """The quick start of issue 25: 2 s of start-up (imports, model, numba) in which 2.3 % is done, then the
    rest in 1.8 s.  elapsed / fraction said ~85 s left at 2 s; the estimate from the run's own rate after
    the start-up gives the true time left (exact for a steady pace, up to the printed 0.1 s)."""
    startup, rest = 2.0, 1.8

    def fraction(t):
        return 0.023 * t / startup if t < startup else 0.023 + 0.977 * (t - startup) / rest

    clock, stream = Clock(), io.StringIO()
    progress = Progress("run", stream=stream, delay=0.0, interval=0.0, clock=clock)
    progress.tty, progress.interval = True, 0.0  # every call may print (a refreshed terminal line)
    _run(fraction, startup + rest, clock, progress)
    lines = stream.getvalue().split("\r")
    assert any("left: measuring" in line for line in lines)  # within the start-up: no number yet
    estimates = [(float(m[2]), float(m[3])) for m in map(LEFT.search, lines) if m]
    assert estimates, lines[:5]
    first_elapsed = estimates[0][0]
    assert first_elapsed >= 2.0 + 1.0 - 0.01  # settle 2 s, then 1 s of measured progress (one clock tick, 0.01 s)
    for elapsed, left in estimates:
        assert left == pytest.approx(startup + rest - elapsed, abs=0.051)  # 6.1f rounding of both numbers
    # What the old formula said at the first line after 2 s: many times the truth.
    old = 2.0 * (1 - fraction(2.0)) / fraction(2.0)
    assert old > 40 * rest


def test_the_estimate_follows_a_change_of_pace():
    """Half way the run slows to a quarter of its pace: once the measured half-window lies after the
    change, the estimate is exact for the new pace (the old one kept the mean of both)."""
    rate = RateEstimate(start=0.0, settle=2.0)

    def fraction(t):
        return 0.01 * t if t <= 50.0 else 0.5 + 0.0025 * (t - 50.0)

    for k in range(0, 1501):
        t = 0.1 * k
        rate.add(t, fraction(t))
    now = 150.0
    true_left = (1.0 - fraction(now)) / 0.0025
    assert rate.left(now, fraction(now)) == pytest.approx(true_left, rel=1e-9)  # linear: exact up to round-off
    assert now * (1 - fraction(now)) / fraction(now) == pytest.approx(0.5 * true_left)  # elapsed/fraction: half


def test_no_estimate_before_a_second_of_measured_progress_or_without_progress():
    rate = RateEstimate(start=0.0, settle=2.0, min_span=1.0)
    assert math.isnan(rate.left(1.0, 0.1))  # still settling
    rate.add(2.5, 0.2)
    assert math.isnan(rate.left(3.0, 0.3))  # 0.5 s measured
    assert rate.left(3.5, 0.3) == pytest.approx(0.7 * 1.0 / 0.1)
    assert math.isnan(rate.left(4.0, 0.2))  # no progress since the mark
    assert rate.left(4.0, 1.0) == 0.0


def test_marks_are_thinned_on_a_long_run():
    """One mark per 1 % of the time measured: an 8-hour run at 1000 calls a second keeps a few hundred."""
    rate = RateEstimate(start=0.0, settle=2.0)
    for k in range(0, 8 * 3600 * 10):  # 10 calls a second (the count, not the rate, matters)
        t = 0.1 * k
        rate.add(t, t / (8 * 3600))
    assert len(rate.times) < 1500


def test_sweep_time_left_is_measured_after_the_workers_start():
    """Two workers, 4 s to start each (a process, imports, numba), then cells of 1 s in pairs: 20 cells end
    at t = 14 s.  The old elapsed x cells left / cells done said 5 x 18 / 2 = 45 s at the first pair (the
    issue's sweep: ~42 s said, 9 s taken); measured from the first cells done on, the estimate is the truth
    (the runner reports once per batch of cells done, as here)."""
    clock, stream = Clock(), io.StringIO()
    bar = SweepProgress(20, 0, stream=stream, interval=0.0, clock=clock)
    bar.tty, bar.interval = True, 0.0
    finish = [4.0 + 1.0 * (k // 2 + 1) for k in range(20)]  # 5, 5, 6, 6, ..., 14, 14
    seen = []
    for k in range(1401):
        clock.now = 0.01 * k
        done = sum(t <= clock.now + 1e-12 for t in finish)
        if done and (not seen or done != seen[-1][1]):
            bar.update(done, 0)
            match = re.search(r"left ~(\d+) s", stream.getvalue().split("\r")[-1])
            seen.append((clock.now, done, float(match[1]) if match else None))
    assert seen[0][2] is None  # the first pair: the start-up is just behind, no rate yet
    assert len(seen) == 10
    for now, done, left in seen[1:]:
        assert abs(left - (14.0 - now)) <= 0.5 + 1e-9, (now, done, left)  # printed as whole seconds
