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
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    from weftsim.input.params import Scene

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


# Run-time estimate shown before a long run starts.  Wall-clock seconds per crank revolution of
# models/reference.toml at 400 rpm (c = 0.25 mm), measured by `weftsim bench --targets` (issue 12,
# medians of 5 in one warm process, the 2-core machine otherwise idle): the start-up (imports, model
# build, numba cache) is not included.  Other scenes differ by the number of impacts and the step a
# contact needs: the estimate is meant to tell seconds from hours, within ~3x.
SECONDS_PER_REVOLUTION = {
    "reference scipy": 0.8,  # DOP853 at rtol 1e-9 on the compiled right-hand side: 0.78-0.89 s (1st revolution)
    "reference numba": 0.008,  # numba_DOP853 at rtol 1e-5 (the default): 79 ms for 10 revolutions
    # numba_DOP853_RODAS4 at rtol 1e-6, the default with friction (issue 23): 2.3-3.1x the dry default in the
    # same process (c = 0.5 mm, mu = 0.15; docs/performance.md "Friction"), so 3x the figure above.
    "reference numba implicit": 0.024,
    # ... with dry friction at E alone RODAS4 only near the friction ramp, at rtol 1e-7 (issue 36): 1.6x the dry
    # default on that scene (CPU, one process), 1.8-2.1x on the loom at c = 0.02 and 0.1 mm.
    "reference numba sliding": 0.016,
    "exudyn kinematic_tree": 0.10,  # the default path (DOPRI5 rtol 1e-6, numba route): 0.97-1.02 s for 10
    "exudyn rigid_body adaptive": 1.95,  # local error 3e-10 m: 1.94-2.00 s (1st revolution)
}
# Steps of the Runge-Kutta paths grow about as rtol^(-1/4) on this contact (the compiled DOP853: 0.08 s per
# revolution at rtol 1e-9, 10x its cost at 1e-5); the figures above are at these tolerances.
REFERENCE_RTOL = {"reference scipy": 1e-9, "reference numba": 1e-5, "reference numba implicit": 1e-6,
                  "reference numba sliding": 1e-7}
# An explicit method on a stiff joint law (friction's ramp, an oil film) steps at its stability limit, ~1e-9 s
# where the journal sticks: one revolution of c = 0.5 mm, 400 rpm, mu = 0.15 took 1661x the dry run with
# numba_DOP853 and 1437x with the kinematic tree's DOPRI5 (issue 23).  Applied to a path that integrates
# such a joint explicitly.
EXPLICIT_STIFF_FACTOR = 1500.0
EXUDYN_STIFF_FACTOR = 1400.0  # the kinematic tree under solver.exudyn.tree_solver = "explicit"
# The Exudyn engine's implicit paths with friction (issue 23, same scene, medians of 3 in one process): the
# kinematic tree on generalized-alpha with error control 4.3-5.0x its dry run (CPU), the rigid-body model
# 25x its frictionless span (docs/performance.md, "Exudyn engine with friction").
EXUDYN_IMPLICIT_STIFF_FACTOR = 5.0
EXUDYN_RIGID_BODY_STIFF_FACTOR = 25.0
# Recorded step rows per revolution (each contact step adds 3 dense points): the dry default ~7 100 (71 000
# for 10 revolutions of the reference scene), the implicit path with friction ~13 000 (3 200 steps), an
# explicit path with friction ~1e7 (2.5 M steps).  A row of result.npz holds ~20 float64 channels.
STEP_ROWS_PER_REVOLUTION = 7.1e3
IMPLICIT_STEP_ROWS_PER_REVOLUTION = 1.3e4
NPZ_BYTES_PER_ROW = 160.0  # 20 channels x 8 bytes; savez_compressed gains little on these mantissas
LARGE_FILE_BYTES = 200e6  # result.npz above this is announced before the run
# The Exudyn rigid-body model takes fixed steps: its cost is per step (5.5 s for the 75 000 steps of
# one revolution at 400 rpm with h = 2e-6 s, 73 us a step; 16.6 s for 3 revolutions).
EXUDYN_SECONDS_PER_STEP = 7.3e-5
SHOW_ESTIMATE_S = 10.0  # shorter runs end before the line would be read
LONG_RUN_S = 600.0  # above 10 min the estimate is a warning: the user may not have meant it


def _stiff(scene: Scene) -> bool:
    from weftsim.reference import stiff_joints

    return bool(stiff_joints(scene))


def _reference_path(scene: Scene) -> tuple[str, bool]:
    """(key of :data:`SECONDS_PER_REVOLUTION`, whether a stiff joint is integrated explicitly)."""
    from weftsim.reference import compiled_method, switches_by_sliding

    method = compiled_method(scene) or scene.reference_solver.method
    if method == "numba_DOP853_RODAS4" and switches_by_sliding(scene):
        return "reference numba sliding", False
    if "RODAS4" in method:
        return "reference numba implicit", False
    path = "reference numba" if method.startswith("numba") else "reference scipy"
    implicit_scipy = method in ("Radau", "BDF", "LSODA")
    return path, _stiff(scene) and not implicit_scipy


def estimate_run_time(scene: Scene, engine: str) -> float:
    """Estimated wall-clock seconds of one run of ``scene`` with ``engine`` (see
    :data:`SECONDS_PER_REVOLUTION`); 0 for the closed-form ideal joint of the reference engine.

    Knows a stiff joint law (friction, an oil film: :func:`weftsim.reference.stiff_joints`): the reference
    engine's implicit path costs ~3x a dry run, an explicit path on it :data:`EXPLICIT_STIFF_FACTOR` times.
    """
    revolutions = scene.drive.revolutions
    if engine == "reference":
        if scene.is_ideal:
            return 0.0
        from weftsim.reference import effective_rtol

        path, explicit_stiff = _reference_path(scene)
        scale = (REFERENCE_RTOL[path] / effective_rtol(scene)) ** 0.25
        return revolutions * SECONDS_PER_REVOLUTION[path] * scale * (EXPLICIT_STIFF_FACTOR if explicit_stiff else 1.0)
    from weftsim.exudyn_engine.selection import select_model
    from weftsim.exudyn_engine.solver import adaptive, step_plan

    stiff = _stiff(scene)
    if select_model(scene)[0] == "kinematic_tree":
        factor = (EXUDYN_STIFF_FACTOR if _exudyn_tree_explicit(scene) else EXUDYN_IMPLICIT_STIFF_FACTOR) if stiff else 1.0
        return revolutions * SECONDS_PER_REVOLUTION["exudyn kinematic_tree"] * factor
    if adaptive(scene):
        factor = EXUDYN_RIGID_BODY_STIFF_FACTOR if stiff else 1.0
        return revolutions * SECONDS_PER_REVOLUTION["exudyn rigid_body adaptive"] * factor
    return step_plan(scene)[1] * EXUDYN_SECONDS_PER_STEP  # the fixed steps it will take (longer for an ideal joint)


def stiff_explicit(scene: Scene, engines: tuple[str, ...]) -> bool:
    """True when one of ``engines`` integrates a stiff joint law of ``scene`` with an explicit method."""
    if not _stiff(scene):
        return False
    exudyn_explicit = "exudyn" in engines and _exudyn_tree_explicit(scene)
    return exudyn_explicit or ("reference" in engines and not scene.is_ideal and _reference_path(scene)[1])


def _exudyn_tree_explicit(scene: Scene) -> bool:
    """True when the Exudyn engine runs ``scene`` on the kinematic tree with its explicit solver."""
    from weftsim.exudyn_engine.selection import select_model
    from weftsim.exudyn_engine.tree_solve import tree_solver

    return select_model(scene)[0] == "kinematic_tree" and tree_solver(scene) == "explicit"


def estimate_step_bytes(scene: Scene, engine: str) -> float:
    """Estimated bytes of the per-step table of one run (``result.npz``, and about as much memory while held).

    The reference engine's rows per revolution (:data:`STEP_ROWS_PER_REVOLUTION`), x
    :data:`EXPLICIT_STIFF_FACTOR` on an explicit path with a stiff joint law; the Exudyn engine's in proportion
    to its estimated time (its steps cost about the same everywhere).
    """
    if engine == "reference":
        if scene.is_ideal:
            return 0.0
        path, explicit_stiff = _reference_path(scene)
        rows = IMPLICIT_STEP_ROWS_PER_REVOLUTION if path == "reference numba implicit" else STEP_ROWS_PER_REVOLUTION
        rows *= EXPLICIT_STIFF_FACTOR if explicit_stiff else 1.0
    else:
        dry = SECONDS_PER_REVOLUTION["exudyn kinematic_tree"]
        rows = STEP_ROWS_PER_REVOLUTION * estimate_run_time(scene, engine) / max(scene.drive.revolutions, 1e-12) / dry
    return rows * scene.drive.revolutions * NPZ_BYTES_PER_ROW


def format_duration(seconds: float) -> str:
    """``"45 s"``, ``"12 min"``, ``"3.1 h"``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
