"""Entry point of the Exudyn engine: ``solve(scene, progress=None) -> RunResult``.

Generalized-alpha (implicit, fixed step) with the settings of ``scene.exudyn_solver``:
step size, spectral radius, modified Newton, Newton relative tolerance and maximum
iterations.  The step is shortened (never lengthened) so that a whole number of steps
fits between output samples; samples are then stored states, not interpolations.

Failures never pass silently: Newton non-convergence (``discontinuous.ignoreMaxIterations``
is off, so Exudyn stops instead of going on), NaN (``exudyn.SolverError``), an exception
in a user function and non-finite channels all give ``status = "failed"`` with a message
naming the time, the crank angle and what to try; the steps computed before are kept.
No files are written (solution and sensor files off) and the solver prints nothing.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
from typing import TYPE_CHECKING

import exudyn as exu

from weftsim.exudyn_engine.callbacks import route_error
from weftsim.exudyn_engine.clearance_joint import register_post_step
from weftsim.exudyn_engine.mechanism import build_mechanism
from weftsim.exudyn_engine.selection import (  # noqa: F401 (IDEAL_JOINT_STEP_ANGLE, requested_step: re-exported)
    IDEAL_JOINT_STEP_ANGLE,
    adaptive,
    requested_step,
    roundoff_problem,
    select_model,
    select_path,
    step_plan,
)
from weftsim.exudyn_engine.step_control import StepController, failure_reason
from weftsim.exudyn_engine.sensors import add_sensors, first_nonfinite_row, sample_channels, silence, step_channels
from weftsim.checks.guards import RunGuard, failure_message, non_finite_breach, raised_min_step
from weftsim.input.params import Scene
from weftsim.input.scene import IMPACT_VELOCITY_RULES, STEP_CONTROLS
from weftsim.post.results import RunResult, angle_grid, empty_channels

if TYPE_CHECKING:
    from collections.abc import Callable

MODELS = ("auto", "rigid_body", "kinematic_tree")  # auto: selection.py; kinematic_tree: tree.py, tree_solve.py
# Modified Newton: iterations with one Jacobian before it is updated.  3 instead of
# Exudyn's 8: 3.75 instead of 5.9 iterations per step, ~30 % less time, identical results
# at the same tolerance (2: 2.97 iterations but 4x the Jacobians, slower).
MODIFIED_NEWTON_ITERATIONS = 3
_PROGRESS_CALLS = 1000  # every 0.1 % of the run: a long run shows its first line soon (issue 16)


def check_settings(scene: Scene) -> str | None:
    """Message naming the first invalid Exudyn-engine setting, or None."""
    s = scene.exudyn_solver
    if s.model not in MODELS:
        return f"`solver.exudyn.model` must be one of {MODELS}, got {s.model!r}"
    if select_model(scene)[0] == "kinematic_tree":
        from weftsim.exudyn_engine.tree_solve import check_tree_settings

        problem = check_tree_settings(scene)
        if problem is not None:
            return problem
    if not (s.step_size > 0.0 and math.isfinite(s.step_size)):
        return f"`solver.exudyn.step_size_s` must be > 0, got {s.step_size}"
    if not 0.0 <= s.spectral_radius <= 1.0:
        return f"`solver.exudyn.spectral_radius` must be in [0, 1], got {s.spectral_radius}"
    if not s.newton_relative_tolerance > 0.0:
        return f"`solver.exudyn.newton_relative_tolerance` must be > 0, got {s.newton_relative_tolerance}"
    if not s.newton_max_iterations >= 1:
        return f"`solver.exudyn.newton_max_iterations` must be >= 1, got {s.newton_max_iterations}"
    if s.step_control not in STEP_CONTROLS:
        return f"`solver.exudyn.step_control` must be one of {STEP_CONTROLS}, got {s.step_control!r}"
    if not scene.output.sample_angle > 0.0:
        return f"`output.sample_deg` must be > 0, got {math.degrees(scene.output.sample_angle):g}"
    if roundoff_problem(scene):
        return roundoff_problem(scene)
    if not (s.local_error > 0.0 and math.isfinite(s.local_error)):
        return f"`solver.exudyn.local_error_m` must be > 0 (m), got {s.local_error}"
    route_problem = route_error(s.callback)
    if route_problem:
        return f"`solver.exudyn.{route_problem[1:]}"
    if s.callback == "numba" and not scene.is_ideal:
        try:
            import numba  # noqa: F401 - optional dependency of this route only
        except ImportError:
            return "`solver.exudyn.callback` = 'numba' needs numba installed; use 'auto' or 'python'"
    if not scene.output.sample_angle > 0.0:
        return f"`output.sample_deg` must be > 0, got {math.degrees(scene.output.sample_angle):g}"
    for table, joint in (("joint_e", scene.joint), ("joint_f", scene.joint_f)):
        if joint.is_ideal:
            continue
        if joint.impact_velocity_rule not in IMPACT_VELOCITY_RULES:
            return (f"`{table}.impact_velocity_rule` must be one of {IMPACT_VELOCITY_RULES}, "
                    f"got {joint.impact_velocity_rule!r}")  # fmt: skip
    if scene.joint_f.friction_coefficient > 0.0 and not scene.joint_f.is_ideal:
        return ("the Exudyn engine has no friction in the clearance joint at F yet (at E it has); "
                "set `joint_f.friction_coefficient` = 0 or use the reference engine")  # fmt: skip
    return None


def simulation_settings(scene: Scene, n_steps: int) -> exu.SimulationSettings:
    """Exudyn settings: generalized-alpha from ``scene.exudyn_solver``, no files, no console output."""
    s = scene.exudyn_solver
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = scene.drive.end_time
    ti.numberOfSteps = n_steps
    ti.generalizedAlpha.spectralRadius = s.spectral_radius
    ti.newton.useModifiedNewton = s.modified_newton
    ti.newton.maxModifiedNewtonIterations = MODIFIED_NEWTON_ITERATIONS
    ti.newton.relativeTolerance = s.newton_relative_tolerance
    ti.newton.maxIterations = s.newton_max_iterations
    ti.discontinuous.ignoreMaxIterations = False
    lubricated = any(j.is_lubricated and not j.is_ideal for j in (scene.joint, scene.joint_f))
    if (scene.joint.friction_coefficient > 0.0 and not scene.joint.is_ideal) or lubricated:
        # The friction moments are torque loads reading the state (joint_friction.py): their dependence on
        # coordinates and velocities (the ramp's slope mu F_N / (v1 - v0) ~ 1e8 N s/m) enters Newton's
        # Jacobian only so, and only a fresh Jacobian follows the journal from sliding into sticking.
        # Measured on the loom (c = 0.25 mm, mu = 0.15, h = 2e-6 s): modified Newton, or full Newton
        # without the loads' velocity Jacobian (computeLoadsJacobian 0 or 1), fail at 103 deg with a
        # step-size collapse; full Newton with it runs (1.7 iterations per step).  Without friction: unchanged.
        # A lubricated joint's film torques and boundary friction are such loads too (joint_friction.py).
        ti.computeLoadsJacobian = 2
        ti.newton.useModifiedNewton = False
    # Newton failures halve the step down to this floor; then the run fails (step-size collapse).
    ti.minimumStepSize = scene.limits.min_step
    if adaptive(scene):
        # The controller sets every step from its post-step hook (the first one at t = 0: one output
        # sample, free flight from the centred journal); Exudyn's own lengthening after easy Newton
        # steps is off.  numberOfSteps only sets Exudyn's initial and largest step.
        ti.numberOfSteps = max(1, math.ceil(scene.drive.end_time * scene.drive.speed / scene.output.sample_angle))
        ti.adaptiveStep = True
        ti.adaptiveStepRecoverySteps = 2**30
    silence(ss)
    return ss


def _failed(scene: Scene, message: str, wall: float) -> RunResult:
    empty = empty_channels(not scene.joint_f.is_ideal)
    return RunResult(scene, "exudyn", "failed", message, empty, empty,
                     {"wall_time_s": wall}, {"first_contact_time_s": None})  # fmt: skip


def _what_to_try(scene: Scene, h: float, collapsed: bool = False) -> str:
    s = scene.exudyn_solver
    floor = raised_min_step(scene) if collapsed else ""  # Newton's step reduction stopped at limits.min_step_s
    if adaptive(scene):
        return (f"try {floor}a smaller `solver.exudyn.local_error_m` (now {s.local_error:.3g} m), or "
                f"`solver.exudyn.step_control` = 'fixed' with a small `solver.exudyn.step_size_s`, a "
                f"`solver.exudyn.spectral_radius` below {s.spectral_radius} or more "
                f"`solver.exudyn.newton_max_iterations` (now {s.newton_max_iterations})")  # fmt: skip
    return (f"try {floor}a smaller `solver.exudyn.step_size_s` (now {h:.3g} s), a `solver.exudyn.spectral_radius` below "
            f"{s.spectral_radius} or more `solver.exudyn.newton_max_iterations` "
            f"(now {s.newton_max_iterations})")  # fmt: skip


def solve(scene: Scene, progress: Callable[[float], None] | None = None, callback: str | None = None,
          observe: Callable[..., None] | None = None) -> RunResult:
    """Simulate a scene with Exudyn: the engine's pure solve (the engine contract, :mod:`weftsim.engines`).

    The result is not vetted here: :func:`weftsim.simulate` runs the before-run checks, this solve, then
    :func:`weftsim.checks.guards.vet_result` once, for every engine.

    Parameters
    ----------
    scene : Scene
    progress : callable, optional
        Called with the completed fraction in [0, 1] about 100 times per run.
    callback : str, optional
        Override of ``scene.exudyn_solver.callback`` (clearance force route).
    observe : callable, optional
        Kinematic tree only (a failed result on another model): called once after the run as
        ``observe(t, states, f_n, v_t)`` with the rows behind ``result.steps``
        (:func:`weftsim.exudyn_engine.tree_solve.solve_tree`), as the reference engine's
        ``solve(observe=...)``; the wear prediction's Archard integral reads them.

    Returns
    -------
    RunResult
        Channels at every accepted step and on the output grid; ``solver_stats`` with
        steps, Newton iterations, Jacobians, contact events, route, step size and wall
        time; ``events["first_contact_time_s"]`` located within its step.
    """
    if scene.rapier_tape is not None:
        return _solve_tape_scene(scene, progress, callback, observe)
    wall0 = _time.perf_counter()
    if callback is not None:  # the route is part of the scene the selection sees (selection.py)
        scene = dataclasses.replace(scene, exudyn_solver=dataclasses.replace(scene.exudyn_solver, callback=callback))
    problem = check_settings(scene)
    if problem is not None:
        return _failed(scene, problem, 0.0)
    path = select_path(scene)
    if observe is not None and path["model"] != "kinematic_tree":
        return _failed(scene, "observe: the Exudyn engine gives the step rows of the kinematic tree only, and "
                              f"this scene runs on the {path['model']} model", 0.0)
    result = _solve_model(scene, path["model"], progress, None, wall0, observe)
    object.__setattr__(result, "path", path)
    return result


def tape_problem(scene: Scene) -> str | None:
    """Why the Exudyn engine cannot run the flexible tape of ``scene`` (one line), or None.

    The tape rides on the kinematic tree (:mod:`.tape_tree`): it needs what the reference engine's tape needs
    (:func:`weftsim.model.tape_selection.flexible_problem`), the settings of the linkage it drives, and the
    tree."""
    from weftsim.model.tape import massless_rapier
    from weftsim.model.tape_selection import flexible_problem

    problem = flexible_problem(scene) or check_settings(massless_rapier(scene))
    if problem is not None:
        return problem
    if select_model(scene)[0] != "kinematic_tree":
        return ("the Exudyn engine runs the flexible rapier tape on the kinematic tree only; set "
                "`solver.exudyn.model` = 'auto' or 'kinematic_tree', or rapier_tape.model = 'rigid'")
    return None


def _solve_tape_scene(scene: Scene, progress, callback, observe) -> RunResult:
    """A scene with a ``[rapier_tape]``: its rigid equivalent when the tape runs as the rigid rapier
    (:func:`weftsim.model.tape_selection.tape_model`), else the flexible tape on the kinematic tree
    (:mod:`.tape_tree`)."""
    from weftsim.model.tape_selection import rigid_scene, tape_check

    check = tape_check(scene)
    if check["model"] == "flexible":
        wall0 = _time.perf_counter()
        if callback is not None:
            scene = dataclasses.replace(scene, exudyn_solver=dataclasses.replace(scene.exudyn_solver,
                                                                                 callback=callback))
        problem = tape_problem(scene)
        if problem is not None:
            return _failed(scene, problem, 0.0)
        from weftsim.exudyn_engine.tree_solve import solve_tree

        result = solve_tree(scene, progress, None, observe)
        object.__setattr__(result, "path", select_path(scene))
        result.solver_stats["wall_time_s"] = _time.perf_counter() - wall0
        return result
    result = solve(rigid_scene(scene), progress, callback, observe)
    object.__setattr__(result, "path", dict(result.path, rapier=check["reason"]))
    object.__setattr__(result, "scene", scene)
    return result


def _solve_model(scene: Scene, path_model: str, progress, callback: str | None, wall0: float,
                 observe: Callable[..., None] | None = None) -> RunResult:
    if path_model == "kinematic_tree":
        from weftsim.exudyn_engine.tree_solve import solve_tree

        return solve_tree(scene, progress, callback, observe)
    h, n_steps = step_plan(scene)
    omega = scene.drive.speed
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    model = build_mechanism(mbs, scene, callback=callback)
    sensors = add_sensors(mbs, model)
    counter = {"steps": 0}
    # The adaptive step takes about 1/3 of the fixed plan's steps (docs/performance.md).
    report_every = max(1, (n_steps // 3 if adaptive(scene) else n_steps) // _PROGRESS_CALLS)
    guard = RunGuard(scene, step_advice=f"a looser solver.exudyn.local_error_m (now {scene.exudyn_solver.local_error:.3g} m)")
    breach = []

    def count(mbs, t):
        counter["steps"] += 1
        if progress is not None and counter["steps"] % report_every == 0:
            # Simulated time, not the step count: the adaptive step's count is not known ahead.
            progress(min(1.0, t / scene.drive.end_time))
        # Exudyn also calls this once at t = 0: not a step.  Runs after the clearance
        # joint's own post-step hook, so the tracker holds this step's penetration.
        found = guard.check(penetration=model.clearance.tracker.delta if model.clearance else None,
                            penetration_f=model.clearance_f.tracker.delta if model.clearance_f else None,
                            steps=1 if t > 0.0 else 0,
                            step_size=control.min_step if control is not None and control.floor_misses else None,
                            floor_fails=True)  # fmt: skip
        if found is not None:
            breach.append(found)
            return False  # Exudyn stops after this step
        return True

    register_post_step(mbs, count)
    solver = exu.MainSolverImplicitSecondOrder()
    control = None
    if adaptive(scene):
        control = StepController.for_mechanism(mbs, solver, model, scene)
        control.install()
    mbs.Assemble()
    for joint in model.clearances.values():
        joint.reset(mbs)
    if progress is not None:
        progress(0.0)
    status, message, kind = "success", "", None
    wall_solve = _time.perf_counter()
    try:
        if not solver.SolveSystem(mbs, simulation_settings(scene, n_steps)):  # type: ignore[call-arg, misc]  # exudyn stub
            status = "failed"
            kind, message = failure_reason(solver, scene)
    except exu.ExudynError as exc:  # NaN (SolverError), user-function exception (ModelError), ...
        text = str(exc).strip().splitlines()
        last = text[-1].split(" [Python file ")[0] if text else ""  # Exudyn appends where it was called from
        status, message = "failed", f"{type(exc).__name__}: {last}"
        kind = ("non_finite" if isinstance(exc, exu.SolverError)
                else "model" if isinstance(exc, exu.ModelError) else "solver")  # fmt: skip
    wall_solve = _time.perf_counter() - wall_solve

    steps = step_channels(mbs, model, sensors)
    bad = first_nonfinite_row(steps)
    if bad is not None:
        steps = {k: v[:bad] for k, v in steps.items()}
        if status == "success":
            found = non_finite_breach("non-finite values (NaN or inf) in the results")
            status, message, kind = "failed", found.what, found.kind
    t_last = float(steps["time_s"][-1]) if len(steps["time_s"]) else 0.0
    if breach and (status == "success" or kind is None):
        # A [limits] criterion stopped the run; its own message says what to try.
        status, kind = "failed", breach[0].kind
        message = failure_message("Exudyn engine", t_last, omega, breach[0].what, breach[0].hint)
    elif status == "failed":
        message = failure_message("Exudyn engine", t_last, omega, message, _what_to_try(scene, h, "step-size collapse" in message))
    elif len(steps["time_s"]) and scene.drive.end_time - steps["time_s"][-1] > 0.5 * h:
        # Fixed steps: a premature stop misses at least one whole step; the time sum itself
        # drifts by ~n_steps * eps * t_end (2.5e-10 s after 10 revolutions), far above 1e-6 h.
        status, kind = "failed", "stopped"
        message = (f"Exudyn stopped at t = {steps['time_s'][-1]:.6g} s before the end time "
                   f"{scene.drive.end_time:.6g} s; {_what_to_try(scene, h)}")  # fmt: skip
    samples = sample_channels(steps, angle_grid(scene.drive.end_time, omega, scene.output.sample_angle))
    it = solver.it
    n_done = max(len(steps["time_s"]) - 1, 0)
    stats = {
        "method": "generalized_alpha",
        "step_control": "adaptive" if control else "fixed",
        # adaptive: the smallest accepted step (the resolution through impacts); fixed: the step.
        "step_size_s": control.counters()["smallest_step_s"] or h if control else h,
        "steps": n_done,
        "rejected_steps": int(it.rejectedModifiedNewtonSteps),
        "newton_iterations": int(it.newtonStepsCount),
        "jacobian_evaluations": int(it.newtonJacobiCount),
        "function_evaluations": int(it.newtonStepsCount),
        **_contact_counters(model),
        "callback": next((c.route for c in model.clearances.values()), None),
        **({k: v for k, v in control.counters().items() if k != "smallest_step_s"} if control else {}),
        "solve_time_s": wall_solve,
        "wall_time_s": _time.perf_counter() - wall0,
    }
    if kind is not None:
        stats["failure"] = kind
    stats["time_per_step_us"] = 1e6 * wall_solve / max(n_done, 1)
    first = {name: c.tracker.first_contact_time for name, c in model.clearances.items()}
    counts = _contact_counters(model) if model.clearances else {}
    events = {"first_contact_time_s": min((v for v in first.values() if v is not None), default=None), **counts}
    if model.clearance_f is not None:
        events.update({f"first_contact_time_{name}_s": first.get(name) for name in ("e", "f")})
    if progress is not None:
        progress(1.0)
    # vetted once, outside the engines, by weftsim.api.simulate (weftsim.checks.guards.vet_result)
    return RunResult(scene, "exudyn", status, message, samples, steps, stats, events)


def _contact_counters(model) -> dict:
    """Contact-history counts of the clearance joints, summed (E's alone keep their values as before)."""
    total = {"contact_events": 0}
    for joint in model.clearances.values():
        for key, value in joint.tracker.counters().items():
            total[key] = total.get(key, 0) + value
    return total
