"""Progress reporting on stderr for long runs (no dependency, no output in tests unless asked)."""

from __future__ import annotations

import sys
import time


class Progress:
    """Callable taking a fraction in [0, 1]; prints at most every ``interval`` s after ``delay`` s.

    Short runs print nothing; long ones show the percentage, elapsed time and an
    estimate of the time left, on one refreshed line when stderr is a terminal.
    """

    def __init__(self, label: str, stream=None, delay: float = 2.0, interval: float = 1.0):
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.delay = delay
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -1.0
        self.shown = False
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        if not self.tty:
            self.interval = max(interval, 10.0)

    def __call__(self, fraction: float) -> None:
        now = time.perf_counter()
        elapsed = now - self.start
        if elapsed < self.delay or now - self.last < self.interval:
            return
        self.last = now
        fraction = min(max(fraction, 0.0), 1.0)
        left = elapsed * (1.0 - fraction) / fraction if fraction > 0 else float("nan")
        text = f"{self.label}: {100 * fraction:5.1f}%  elapsed {elapsed:6.1f} s  left ~{left:6.1f} s"
        self.stream.write(("\r" + text) if self.tty else (text + "\n"))
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown and self.tty:
            self.stream.write("\n")
            self.stream.flush()
