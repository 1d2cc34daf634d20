"""Reference engine: closed-form Lagrange equations integrated with scipy (no Exudyn).

The cross-check engine that plays ADAMS's role for the Exudyn model.  Public entry:

    solve(scene, progress=None, observe=None) -> weftsim.post.results.RunResult   (pure: not vetted)
    ENGINE: its object in the engine registry (:mod:`weftsim.engines`, :mod:`.engine`)

- Ideal joint (``scene.joint.is_ideal``): one coordinate theta, the driving torque
  T = 1/2 J_eq'(theta) omega^2 + U'(theta) in closed form (:mod:`.ideal`); nothing is
  integrated.
- Clearance joint: members 1-3 prescribed by theta = omega t, members 4-8 a 2-DOF chain
  (theta_FG, theta_EF) forced through the contact at E (:mod:`.dynamics`), integrated
  in segments between contact events (:mod:`.integrate`).
- Clearance at F (``scene.joint_f``): alone, again 2 DOF (the rod turns about E of the rocker, the
  sector is driven through the contact at F); with E, the rod is free (4 DOF)
  (:mod:`weftsim.physics.chain_f`).  These run on the compiled path only.

The derivation is in docs/reference-solver.md.
"""

from __future__ import annotations

import math
import time as _time
from typing import TYPE_CHECKING

import numpy as np

from weftsim.input.params import Scene
from weftsim.model.stiffness import stiff_joints
from weftsim.reference.integrate import AUTO, METHODS
from weftsim.post.results import RunResult, empty_channels

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["solve", "select_path", "METHODS", "AUTO", "COMPILED_METHODS", "stiff_joints", "effective_rtol"]

# Steps of the ideal-joint run: the closed form evaluated on a grid this many times finer
# than the output grid (peaks of smooth curves then err by ~(step/2)^2 |f''|/2, < 1e-6 relative).
IDEAL_STEP_REFINEMENT = 5


# weftsim.reference.compiled (needs numba): explicit Runge-Kutta, the linearly implicit RODAS4 on every step,
# or DOP853 in free flight and RODAS4 in contact segments.
COMPILED_METHODS = ("numba_DOP853", "numba_RK45", "numba_RODAS4", "numba_DOP853_RODAS4")


def _check(scene: Scene) -> str | None:
    settings = scene.reference_solver
    allowed = [AUTO] + sorted(METHODS) + list(COMPILED_METHODS)
    if settings.method not in allowed:
        return f"`solver.reference.method` must be one of {allowed}, got {settings.method!r}"
    if compiled_method(scene) is not None:
        try:
            import numba  # noqa: F401 - a dependency; checked for installs that lost it
        except ImportError:
            return f"`solver.reference.method` = {settings.method!r} needs numba installed; use 'DOP853' (scipy)"
    if _flexible_tape(scene) and compiled_method(scene) is None:
        return (f"`solver.reference.method` = {settings.method!r} cannot run the flexible rapier tape: the scipy path "
                f"carries the rigid chain only; use 'auto' or one of {list(COMPILED_METHODS)}")
    if not scene.joint_f.is_ideal and compiled_method(scene) is None:
        return (f"`solver.reference.method` = {settings.method!r} cannot run a clearance at F (joint_f): the scipy "
                f"path carries the clearance at E only; use 'auto' or one of {list(COMPILED_METHODS)}")
    for name, key, scale in (("rtol", "rtol", 1.0), ("atol", "atol", 1.0), ("max_step", "max_step_deg", 180 / math.pi)):
        value = getattr(settings, name)
        if not (value > 0.0 and math.isfinite(value)):
            return f"`solver.reference.{key}` must be > 0, got {value * scale:g}"
    if not scene.output.sample_angle > 0.0:
        return f"`output.sample_deg` must be > 0, got {math.degrees(scene.output.sample_angle):g}"
    return None


def _solve_ideal(scene: Scene, progress) -> RunResult:
    from weftsim.model.ideal import ideal_channels
    from weftsim.post.results import angle_grid

    wall0 = _time.perf_counter()
    omega, t_end = scene.drive.speed, scene.drive.end_time
    samples = ideal_channels(angle_grid(t_end, omega, scene.output.sample_angle), scene)
    fine = angle_grid(t_end, omega, scene.output.sample_angle / IDEAL_STEP_REFINEMENT)
    steps = ideal_channels(fine, scene)
    if progress is not None:
        progress(1.0)
    stats = {
        "method": "closed_form",
        "steps": int(fine.size),
        "rejected_steps": 0,
        "function_evaluations": 0,
        "contact_events": 0,
        "wall_time_s": _time.perf_counter() - wall0,
    }
    return RunResult(scene, "reference", "success", "", samples, steps, stats, {"first_contact_time_s": None})


# With a stiff joint law "auto" integrates contact segments with the linearly implicit RODAS4 at this rtol
# at most: the first-revolution peaks of the friction case (c = 0.5 mm, 400 rpm, mu = 0.15) are then within
# 3e-4 of the converged solution, at 1e-5 the torque peak is 1.1 % high (docs/reference-solver.md section 4).
STIFF_RTOL = 1e-6
# Dry friction at E alone (no film, F ideal): "auto" takes RODAS4 only near the friction ramp (compiled.RAMP_SWITCH)
# and DOP853 in full sliding, whose steps are longer; at 1e-6 the loom's torque peak (c = 0.1 mm, 600 rpm) fell
# between two rows 11.5 us apart, 1.1e-3 low; at this rtol first-revolution peaks are within 9.3e-5 (c = 0.1 mm),
# 4.3e-4 (0.02 mm) and 1.9e-5 (reference scene, 0.5 mm, 400 rpm) of RODAS4 at rtol 1e-10, at 3 664, 3 615 and
# 2 672 steps a revolution (dry: 938, 1 335, 1 267; all on RODAS4 at 1e-6: 16 340 on the loom at 0.1 mm).
SLIDING_RTOL = 1e-7


def compiled_method(scene: Scene) -> str | None:
    """The compiled method (:data:`COMPILED_METHODS`) a clearance scene runs on, or None for scipy.

    ``"auto"`` is ``numba_DOP853`` (scipy's DOP853 step for step, compiled, 10-100x faster,
    docs/performance.md), or with friction (:func:`stiff_joints`) ``numba_DOP853_RODAS4``: DOP853 in free
    flight, the linearly implicit RODAS4 in contact; with a lubricated joint ``numba_RODAS4`` (the film acts
    in free flight too).  A scipy method runs only when named.
    """
    method = scene.reference_solver.method
    if method == AUTO:
        if _flexible_tape(scene):
            # The tape's Ritz modes reach 10^5-10^6 rad/s, overdamped by the Kelvin-Voigt damping: a stiff
            # system for an explicit method (docs/rapier-tape.md); RODAS4's step follows the accuracy alone.
            return "numba_RODAS4"
        if any(j.is_lubricated for j in (scene.joint, scene.joint_f) if not j.is_ideal):
            # The film loads the joint at every step, not in contact segments alone: RODAS4 throughout
            # (loom, 600 rpm, c = 0.02 mm, 80 mPa s, one revolution: 20 897 steps against 363 870 of
            # DOP853 in the film's free-flight segments, torque peak within 7e-4).
            return "numba_RODAS4"
        return "numba_DOP853_RODAS4" if stiff_joints(scene) else "numba_DOP853"
    return method if method in COMPILED_METHODS else None


def _flexible_tape(scene: Scene) -> bool:
    """True when the scene's rapier tape runs flexible (:func:`weftsim.model.tape_selection.tape_model`)."""
    if scene.rapier_tape is None:
        return False
    from weftsim.model.tape_selection import tape_model

    return tape_model(scene) == "flexible"


def effective_rtol(scene: Scene) -> float:
    """The rtol the run uses: the scene's, capped at :data:`STIFF_RTOL` when "auto" chose RODAS4 for friction.

    An oil film alone keeps the scene's rtol: RODAS4 at 1e-5 meets DOP853's first-revolution peaks within
    1.2e-3 on the loom (600 rpm, 80 mPa s, c = 0.02 and 0.1 mm; minimum film ratio within 2e-4), and at 1e-6
    the film's non-smooth cavitation boundary cost 6x the steps (1.15 M per two revolutions at c = 0.1 mm).
    """
    s = scene.reference_solver
    friction = any(j.friction_coefficient > 0.0 for j in (scene.joint, scene.joint_f) if not j.is_ideal)
    if s.method == AUTO and stiff_joints(scene) and friction:
        return min(s.rtol, SLIDING_RTOL if switches_by_sliding(scene) else STIFF_RTOL)
    return s.rtol


def switches_by_sliding(scene: Scene) -> bool:
    """True when "auto" integrates contact with RODAS4 only near the friction ramp (:mod:`.compiled`,
    ``RAMP_SWITCH``): dry friction at E, no oil film, an ideal joint at F."""
    return (not scene.joint.is_ideal and scene.joint.friction_coefficient > 0.0 and not scene.joint.is_lubricated
            and scene.joint_f.is_ideal)


def select_path(scene: Scene) -> dict:
    """``{"model", "method", "reason"}`` of the run :func:`solve` makes of ``scene`` (and ``"rapier"``: the
    tape's verdict, :func:`weftsim.model.tape_selection.tape_check`, when the scene has a ``[rapier_tape]``)."""
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import rigid_scene, tape_check

        check = tape_check(scene)
        path = select_path(rigid_scene(scene)) if check["model"] == "rigid" else _select_path(scene)
        if check["model"] == "flexible":
            path["model"] += f" with the flexible rapier tape ({scene.rapier_tape.modes} Ritz functions)"
        else:
            path["model"] += " with the tape and head as the rigid rapier"
        return dict(path, rapier=check["reason"])
    return _select_path(scene)


def _select_path(scene: Scene) -> dict:
    if scene.is_ideal:
        return {"model": "ideal joint", "method": "closed form",
                "reason": "clearance 0: no free coordinate, nothing to integrate"}
    s = scene.reference_solver
    method = compiled_method(scene) or s.method
    stiff = stiff_joints(scene)
    why = ("solver.reference.method = 'auto': the fastest path meeting the accuracy targets" if s.method == AUTO
           else f"set by solver.reference.method = {s.method!r}")
    if s.method == AUTO and stiff:
        where = ("every step" if method == "numba_RODAS4" else "contact within 10 v1 of the friction ramp"
                 if switches_by_sliding(scene) else "contact segments")
        why += f"; {', '.join(stiff)}: {where} linearly implicit, rtol {effective_rtol(scene):g}"
    model = {("e",): "clearance chain (2 DOF)", ("f",): "clearance at F: chain about E (2 DOF)",
             ("e", "f"): "clearance at E and F: free rod (4 DOF)"}[scene.loose_joints]
    return {"model": model, "method": f"{method} rtol {effective_rtol(scene):g} atol {s.atol:g}", "reason": why}


def _solve_clearance(scene: Scene, progress, observe) -> RunResult:
    method = compiled_method(scene)
    if method is not None:
        from weftsim.reference.compiled_run import solve_compiled

        return solve_compiled(scene, progress, method, observe, rtol=effective_rtol(scene))
    from weftsim.reference.channels import clearance_channels
    from weftsim.reference.integrate import integrate

    traj = integrate(scene, progress)
    if observe is not None:
        states = np.array(traj.step_y).reshape(-1, 6)
        observe(np.array(traj.step_t), states, np.array(traj.step_contact, dtype=bool), np.array(traj.step_impact))
    wall0 = _time.perf_counter()

    def channels(t, y, contact, impact):
        if not t:
            return empty_channels()
        return clearance_channels(scene, np.array(t), np.array(y), np.array(contact), np.array(impact))

    samples = channels(traj.sample_t, traj.sample_y, traj.sample_contact, traj.sample_impact)
    steps = channels(traj.step_t, traj.step_y, traj.step_contact, traj.step_impact)
    stats = dict(traj.stats)
    stats["postprocess_time_s"] = _time.perf_counter() - wall0
    stats["wall_time_s"] = stats["wall_time_s"] + stats["postprocess_time_s"]
    return RunResult(scene, "reference", traj.status, traj.message, samples, steps, stats, traj.events)


def solve(scene: Scene, progress: Callable[[float], None] | None = None,
          observe: Callable[..., None] | None = None) -> RunResult:
    """Run the reference solver on a scene: the engine's pure solve (the engine contract, :mod:`weftsim.engines`).

    The result is not vetted here: :func:`weftsim.simulate` runs the before-run checks, this solve, then
    :func:`weftsim.checks.guards.vet_result` once, for every engine.

    Parameters
    ----------
    scene : Scene
        Every joint ideal (``scene.is_ideal``) selects the closed form; otherwise the
        clearance mode is integrated with ``scene.reference_solver`` (method by name from
        :data:`METHODS` or :data:`COMPILED_METHODS`, or ``"auto"``: the compiled DOP853;
        rtol, atol, max_step as crank angle).  :func:`select_path` says which.
    progress : callable, optional
        Called with the completed fraction in [0, 1].
    observe : callable, optional
        Clearance mode only: called once, after the integration, as
        ``observe(t, y, contact, impact)`` with the raw rows behind ``result.steps``
        (times (N,) s; states (N, 6) [a, psi, a', psi', W3, D]; the segment's mode (N,) bool;
        the held impact velocity (N,) m/s), for analyses that need the state itself, e.g.
        the approach rate at each contact onset (:mod:`weftsim.studies.outliers`).

    Returns
    -------
    RunResult
        ``status = "failed"`` with a message (time, crank angle, what to try) when the
        integration fails; what was computed up to then is kept.  Invalid solver settings
        also give a failed result naming the setting.
    """
    original = scene
    problem = None
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import flexible_problem, rigid_scene

        scene = rigid_scene(scene)
        problem = flexible_problem(scene) if scene.rapier_tape is not None else None
    if problem is None:
        problem = _check(scene)
    if problem is not None:
        empty = empty_channels(not scene.joint_f.is_ideal)
        return RunResult(scene, "reference", "failed", problem, empty, empty,
                         {"wall_time_s": 0.0}, {"first_contact_time_s": None})  # fmt: skip
    if scene.is_ideal:
        result = _solve_ideal(scene, progress)
    else:
        result = _solve_clearance(scene, progress, observe)
    object.__setattr__(result, "path", select_path(original))
    object.__setattr__(result, "scene", original)  # a tape run as the rigid rapier: the scene asked for
    return result  # vetted once, outside the engines, by weftsim.api.simulate (weftsim.checks.guards.vet_result)
