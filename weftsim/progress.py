"""Progress reporting on stderr for long runs (no dependency, no output in tests unless asked)."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from weftsim.params import Scene


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


# Run-time estimate shown before a long run starts.  Wall-clock seconds per crank revolution of
# models/reference.toml at 400 rpm (c = 0.25 mm), measured by `weftsim bench --targets` (issue 12,
# medians of 5 in one warm process, the 2-core machine otherwise idle): the start-up (imports, model
# build, numba cache) is not included.  Other scenes differ by the number of impacts and the step a
# contact needs: the estimate is meant to tell seconds from hours, within ~3x.
SECONDS_PER_REVOLUTION = {
    "reference scipy": 0.8,  # DOP853 at rtol 1e-9 on the compiled right-hand side: 0.78-0.89 s (1st revolution)
    "reference numba": 0.008,  # numba_DOP853 at rtol 1e-5 (the default): 79 ms for 10 revolutions
    "exudyn kinematic_tree": 0.10,  # the default path (DOPRI5 rtol 1e-6, numba route): 0.97-1.02 s for 10
    "exudyn rigid_body adaptive": 1.95,  # local error 3e-10 m: 1.94-2.00 s (1st revolution)
}
# Steps of the Runge-Kutta paths grow about as rtol^(-1/4) on this contact (the compiled DOP853: 0.08 s per
# revolution at rtol 1e-9, 10x its cost at 1e-5); the figures above are at these tolerances.
REFERENCE_RTOL = {"reference scipy": 1e-9, "reference numba": 1e-5}
# The Exudyn rigid-body model takes fixed steps: its cost is per step (5.5 s for the 75 000 steps of
# one revolution at 400 rpm with h = 2e-6 s, 73 us a step; 16.6 s for 3 revolutions).
EXUDYN_SECONDS_PER_STEP = 7.3e-5
SHOW_ESTIMATE_S = 10.0  # shorter runs end before the line would be read
LONG_RUN_S = 600.0  # above 10 min the estimate is a warning: the user may not have meant it


def estimate_run_time(scene: Scene, engine: str) -> float:
    """Estimated wall-clock seconds of one run of ``scene`` with ``engine`` (see
    :data:`SECONDS_PER_REVOLUTION`); 0 for the closed-form ideal joint of the reference engine."""
    revolutions = scene.drive.revolutions
    if engine == "reference":
        if scene.is_ideal:
            return 0.0
        from weftsim.reference import select_path

        path = "reference numba" if "numba" in select_path(scene)["method"] else "reference scipy"
        scale = (REFERENCE_RTOL[path] / scene.reference_solver.rtol) ** 0.25
        return revolutions * SECONDS_PER_REVOLUTION[path] * scale
    from weftsim.exudyn_engine.selection import select_model
    from weftsim.exudyn_engine.solver import adaptive, step_plan

    if select_model(scene)[0] == "kinematic_tree":
        return revolutions * SECONDS_PER_REVOLUTION["exudyn kinematic_tree"]
    if adaptive(scene):
        return revolutions * SECONDS_PER_REVOLUTION["exudyn rigid_body adaptive"]
    return step_plan(scene)[1] * EXUDYN_SECONDS_PER_STEP  # the fixed steps it will take (longer for an ideal joint)


def format_duration(seconds: float) -> str:
    """``"45 s"``, ``"12 min"``, ``"3.1 h"``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
