"""Driver of the compiled reference path: runs :func:`weftsim.reference.compiled.advance` in
chunks (progress, wall-time budget, buffers), applies the run guards of :mod:`weftsim.checks.guards`
and builds the :class:`~weftsim.post.results.RunResult` with the compiled channels.

Entry: :func:`solve_compiled` (``reference_solver.method`` = ``"numba_DOP853"``, ``"numba_RK45"``,
``"numba_RODAS4"`` or ``"numba_DOP853_RODAS4"``).
"""

from __future__ import annotations

import math
import time as _time
from typing import TYPE_CHECKING

import numpy as np

from weftsim.checks.guards import RunGuard, failure_message, memory_breach, non_finite_breach
from weftsim.input.params import Scene
from weftsim.reference.compiled import (
    DECOMPOSITIONS, DENSE, DONE, EVENTS, IMPLICIT_STEPS, JACOBIANS, FIRST_CONTACT, FIRST_CONTACT_F, GUARD, IMPACTS, LAST_PENETRATION, LAST_PENETRATION_F,
    LAST_STEP, MAX_RATE, METHODS, N_FLOAT_STATE, N_INT_STATE, NEXT_SAMPLE, NFEV, NON_FINITE, NONPOSITIVE, PAUSED,
    PEAKS, REJECTED, SEGMENTS, START, STEP_TOO_SMALL, STEPS, T, _STEP_BUFFER,
    advance, advance_plain,
)  # fmt: skip
from weftsim.physics.chain_f import N_JOINTS, is_plain
from weftsim.post import npz_guard
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.reference.integrate import _PROGRESS_EVERY
from weftsim.post.results import RunResult

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["integrate_compiled", "solve_compiled", "METHODS"]


def _empty_buffers(n: int, size: int):
    """Rows of (t, state (n, size), contact mask, held impact velocities (n, 2) at E and F)."""
    return np.zeros(n), np.zeros((n, size)), np.zeros(n, dtype=np.uint8), np.zeros((n, N_JOINTS))


def _rows(scene: Scene, rows):
    """Rows as the callers take them: with clearance at E alone the contact flag (bool) and E's held
    impact velocity (n,), as the scipy path gives them; with clearance at F the mask and both columns."""
    t, y, mask, impact = rows
    if scene.joint_f.is_ideal:
        return t, y, (mask & 1).astype(bool), impact[:, 0].copy()
    return t, y, mask, impact


def integrate_compiled(scene: Scene, progress: Callable[[float], None] | None = None,
                       method: str = "numba_DOP853",
                       rtol: float | None = None) -> tuple[tuple, tuple, dict, dict, str, str]:
    """Run the compiled integrator; returns (steps, samples, stats, events, status, message).

    ``rtol``: the relative tolerance, default ``scene.reference_solver.rtol``
    (:func:`weftsim.reference.effective_rtol` caps it for a stiff joint under "auto").

    ``steps`` and ``samples`` are tuples (t, y (n, 6 or 10), contact mask (bit 0 E, bit 1 F), held
    impact velocities (n, 2)) as :func:`weftsim.reference.compiled_channels.compiled_channels` takes them.
    """
    settings = scene.reference_solver
    omega, t_end = scene.drive.speed, scene.drive.end_time
    code_method = METHODS[method]
    wall0 = _time.perf_counter()
    prm = pack_parameters(scene)
    sample_dt = scene.output.sample_angle / omega
    n_samples = int(math.floor(t_end / sample_dt * (1.0 + 1e-12))) + 1
    sample_times = np.arange(n_samples) * sample_dt
    if t_end - sample_times[-1] > 1e-9 * sample_dt:
        sample_times = np.append(sample_times, t_end)
    y = initial_state(scene).astype(float)
    f = np.zeros(y.size)
    fst = np.zeros(N_FLOAT_STATE)
    fst[FIRST_CONTACT] = fst[FIRST_CONTACT_F] = -1.0
    fst[LAST_PENETRATION] = fst[LAST_PENETRATION_F] = -math.inf
    fst[LAST_STEP] = math.inf
    ist = np.zeros(N_INT_STATE, dtype=np.int64)
    ist[START] = 1
    guard = RunGuard(scene)
    limits = np.array([math.inf if scene.joint.is_ideal else guard.max_penetration, guard.min_step,
                       float(guard.max_steps or 0),
                       math.inf if scene.joint_f.is_ideal else guard.max_penetration_f])  # fmt: skip
    smp = _empty_buffers(sample_times.size, y.size)
    stp = _empty_buffers(_STEP_BUFFER, y.size)
    chunks = [(np.zeros(1), y[None, :].copy(), np.zeros(1, dtype=np.uint8), np.zeros((1, N_JOINTS)))]
    if progress is not None:
        progress(0.0)
    # Pause every 1 % of the run for progress reports and the wall-time budget only if needed.
    pausing = progress is not None or math.isfinite(guard.max_wall_time)
    next_report = _PROGRESS_EVERY
    status, message, failure = "success", "", None
    # scipy raises rtol below 100 eps to it (a warning); the compiled path does the same, silently.
    rtol_asked = settings.rtol if rtol is None else rtol
    rtol = max(rtol_asked, 100.0 * np.finfo(float).eps)
    steps_seen = 0
    recorded = 1  # rows in chunks
    available = npz_guard.available_memory()  # the rows' budget: half of what the machine can give now
    memory = math.inf if available is None else 0.5 * available
    kernel = advance_plain if is_plain(prm) else advance
    while True:
        t_pause = next_report * t_end if pausing else 2.0 * t_end
        code, rows = kernel(prm, code_method, rtol, settings.atol, settings.max_step / omega, t_end,
                             t_pause, limits, y, f, fst, ist, sample_times, *smp, *stp)  # fmt: skip
        chunks.append(tuple(b[:rows].copy() for b in stp))
        recorded += rows
        t = fst[T]
        breach = None
        if code == GUARD:
            # -inf marks a step out of contact (no penetration to check), not a non-finite state
            breach = guard.check(penetration=_in_contact(fst[LAST_PENETRATION], scene.joint.is_ideal),
                                 penetration_f=_in_contact(fst[LAST_PENETRATION_F], scene.joint_f.is_ideal),
                                 step_size=fst[LAST_STEP], steps=int(ist[STEPS]) - steps_seen)  # fmt: skip
        elif code == STEP_TOO_SMALL:
            breach = guard.check(step_size=10.0 * np.spacing(t), steps=0)
        elif code == NON_FINITE:
            breach = non_finite_breach("the right-hand side or the state turned non-finite (NaN or inf)")
        elif code != DONE:
            breach = guard.check(steps=int(ist[STEPS]) - steps_seen)  # the wall-time budget
        if breach is None:  # checked at every return of advance: the rows overshoot by one buffer at most
            breach = memory_breach(recorded, memory)
        steps_seen = int(ist[STEPS])
        if breach is not None:
            status, failure = "failed", breach.kind
            message = failure_message(f"reference solver ({method})", t, omega, breach.what, breach.hint)
            break
        if code == DONE:
            break
        if code == PAUSED and progress is not None:
            progress(min(t / t_end, 1.0))
        if code == PAUSED:
            next_report = math.floor(t / t_end / _PROGRESS_EVERY + 1.0) * _PROGRESS_EVERY
    wall = _time.perf_counter() - wall0
    steps = tuple(np.concatenate([c[i] for c in chunks]) for i in range(4))
    n_done = int(ist[NEXT_SAMPLE])
    samples = tuple(b[:n_done] for b in smp)
    steps, samples = _rows(scene, steps), _rows(scene, samples)
    stats = {
        "method": method,
        "rtol": rtol_asked,
        "atol": settings.atol,
        "max_step_rad": settings.max_step,
        "steps": int(ist[STEPS]),
        "rejected_steps": int(ist[REJECTED]),
        "function_evaluations": int(ist[NFEV]),
        "jacobian_evaluations": int(ist[JACOBIANS]),
        "lu_decompositions": int(ist[DECOMPOSITIONS]),
        "implicit_steps": int(ist[IMPLICIT_STEPS]),
        "dense_output_calls": int(ist[DENSE]),
        "segments": int(ist[SEGMENTS]),
        "contact_events": int(ist[EVENTS]),
        "impacts": int(ist[IMPACTS]),
        "rate_peaks": int(ist[PEAKS]),
        "nonpositive_onsets": int(ist[NONPOSITIVE]),
        "wall_time_s": wall,
    }
    first = {joint: None if fst[slot] < 0.0 else float(fst[slot])
             for joint, slot in (("e", FIRST_CONTACT), ("f", FIRST_CONTACT_F))}
    events = {
        # The first onset at any joint (E's alone in an E-only scene, as before).
        "first_contact_time_s": min((v for v in first.values() if v is not None), default=None),
        "max_impact_velocity_m_s": float(fst[MAX_RATE]),
    }
    if not scene.joint_f.is_ideal:
        events.update({f"first_contact_time_{joint}_s": value for joint, value in first.items()})
    if failure is not None:
        stats["failure"] = failure
    if progress is not None and status == "success":
        progress(1.0)
    return steps, samples, stats, events, status, message


def _in_contact(penetration: float, ideal: bool) -> float | None:
    """The last step's penetration for the guard: None at an ideal joint or a step out of contact (-inf)."""
    return None if ideal or penetration == -math.inf else float(penetration)


def solve_compiled(scene: Scene, progress: Callable[[float], None] | None = None, method: str | None = None,
                   observe: Callable[..., None] | None = None, rtol: float | None = None) -> RunResult:
    """The reference engine's clearance mode through the compiled integrator.

    ``method``: one of :data:`METHODS`; default ``scene.reference_solver.method``.
    ``observe``: optional callable given the raw step rows (t, y, contact, impact), as
    in :func:`weftsim.reference.solve`.
    """
    from weftsim.reference.compiled_channels import compiled_channels
    from weftsim.post.results import empty_channels

    steps, samples, stats, events, status, message = integrate_compiled(
        scene, progress, method or scene.reference_solver.method, rtol)
    if observe is not None:
        observe(*steps)
    wall0 = _time.perf_counter()

    fill = compiled_channels
    if scene.rapier_tape is not None:  # the flexible tape (a rigid one arrives as its rigid equivalent)
        from weftsim.reference.tape_channels import tape_channels as fill

    def channels(arrays):
        return fill(scene, *arrays) if arrays[0].size else empty_channels(not scene.joint_f.is_ideal)

    step_channels, sample_channels = channels(steps), channels(samples)
    stats["postprocess_time_s"] = _time.perf_counter() - wall0
    stats["wall_time_s"] += stats["postprocess_time_s"]
    return RunResult(scene, "reference", status, message, sample_channels, step_channels, stats, events)
