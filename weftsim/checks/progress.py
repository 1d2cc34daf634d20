"""Progress reporting on stderr for long runs (no dependency, no output in tests unless asked).

The time left is measured from the run's own progress, after its start-up (:class:`RateEstimate`): the
first seconds of a run import modules, build the model and compile the numba kernels while the fraction
done hardly moves, so elapsed / fraction would first overestimate the rest many times over (issue 25:
"left ~84.8 s" on a run that ended 1.8 s later).
"""

from __future__ import annotations

import bisect
import math
import sys
import time
from typing import Callable

SETTLE_S = 2.0  # the start-up a rate is not measured over: imports, model build, numba compilation (~1-2 s)
MIN_SPAN_S = 1.0  # the shortest stretch of progress a rate is measured over (a shorter one is noise)


class RateEstimate:
    """Time left of a run from its own rate of progress, measured after its start-up.

    Marks ``(time, fraction)`` are kept from ``settle`` seconds after ``start`` on (thinned: at most one per
    1 % of the time measured so far, so an hours-long run keeps a few hundred).  The rate is taken over
    the latter half of the measured stretch, so it follows a run whose pace changes (a sweep's first
    cells include the workers' start-up; a run's impacts cluster) and forgets the start-up entirely.

    Parameters
    ----------
    start : float
        The clock reading at the start of the run, s.
    settle : float
        Seconds after ``start`` before marks are kept (:data:`SETTLE_S`).
    min_span : float
        The shortest stretch, s, a rate is measured over; until then the time left is unknown (NaN).
    """

    def __init__(self, start: float, settle: float = SETTLE_S, min_span: float = MIN_SPAN_S):
        self.start, self.settle, self.min_span = start, settle, min_span
        self.times: list[float] = []
        self.fractions: list[float] = []

    def add(self, now: float, fraction: float) -> None:
        """Record the fraction done at clock reading ``now``."""
        if now - self.start < self.settle:
            return
        if self.times:
            spacing = max(0.01 * (now - self.times[0]), 1e-3)
            if fraction <= self.fractions[-1] or now - self.times[-1] < spacing:
                return
        self.times.append(now)
        self.fractions.append(fraction)

    def left(self, now: float, fraction: float) -> float:
        """Seconds left at clock reading ``now`` with ``fraction`` done (NaN while the rate is unknown)."""
        if not self.times or fraction >= 1.0:
            return 0.0 if fraction >= 1.0 else math.nan
        middle = self.times[0] + 0.5 * (now - self.times[0])
        i = max(bisect.bisect_right(self.times, middle) - 1, 0)  # the last mark in the first half
        span, gained = now - self.times[i], fraction - self.fractions[i]
        if span < self.min_span or gained <= 0.0:
            return math.nan
        return (1.0 - fraction) * span / gained


class Progress:
    """Callable taking a fraction in [0, 1]; prints at most every ``interval`` s after ``delay`` s.

    Short runs print nothing; long ones show the percentage, elapsed time and an
    estimate of the time left (:class:`RateEstimate`), on one refreshed line when stderr is a
    terminal.  ``clock`` (seconds, monotonic) is :func:`time.perf_counter` unless a test gives its own.
    """

    def __init__(self, label: str, stream=None, delay: float = 2.0, interval: float = 1.0,
                 clock: Callable[[], float] = time.perf_counter, settle: float = SETTLE_S):
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.delay = delay
        self.interval = interval
        self.clock = clock
        self.start = clock()
        self.rate = RateEstimate(self.start, settle)
        self.last = -math.inf
        self.shown = False
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        if not self.tty:
            self.interval = max(interval, 10.0)

    def __call__(self, fraction: float) -> None:
        now = self.clock()
        fraction = min(max(fraction, 0.0), 1.0)
        self.rate.add(now, fraction)
        elapsed = now - self.start
        if elapsed < self.delay or now - self.last < self.interval:
            return
        left = self.rate.left(now, fraction)
        self.last = now
        shown = f"left ~{left:6.1f} s" if math.isfinite(left) else "left: measuring"
        text = f"{self.label}: {100 * fraction:5.1f}%  elapsed {elapsed:6.1f} s  {shown}"
        self._write(("\r" + text) if self.tty else (text + "\n"))
        self.shown = True

    def _write(self, text: str) -> None:
        """Write, or stop reporting when the stream is gone (stderr piped into ``head`` that exited):
        a progress line must never end the run it reports on."""
        if self.stream is None:
            return
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # BrokenPipeError, a closed file
            self.stream = None

    def close(self) -> None:
        if self.shown and self.tty:
            self._write("\n")


# The engines' run-time and memory estimates are theirs (the engine contract's ``estimate``:
# weftsim.reference.engine, weftsim.exudyn_engine.engine); what is common to both is here.
# Recorded step rows per revolution (each contact step adds 3 dense points): the dry default ~7 100 (71 000
# for 10 revolutions of the reference scene), an explicit path with friction ~1e7 (2.5 M steps).  A row of
# result.npz holds ~20 float64 channels.
STEP_ROWS_PER_REVOLUTION = 7.1e3
NPZ_BYTES_PER_ROW = 160.0  # 20 channels x 8 bytes; savez_compressed gains little on these mantissas
LARGE_FILE_BYTES = 200e6  # result.npz above this is announced before the run
SHOW_ESTIMATE_S = 10.0  # shorter runs end before the line would be read
LONG_RUN_S = 600.0  # above 10 min the estimate is a warning: the user may not have meant it


def format_duration(seconds: float) -> str:
    """``"45 s"``, ``"12 min"``, ``"3.1 h"``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
