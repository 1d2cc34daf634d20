"""Which Exudyn model and method a scene runs on (``RunResult.path``): the automatic selection.

``solver.exudyn.model = "auto"`` (the default) picks the smallest model that carries the scene:

- **kinematic tree** (:mod:`.tree`, :mod:`.tree_solve`) when members 1-3 are ideal and rigid and
  the clearance joint at E is the only free joint.  Then the crank, coupler and rocker move in
  closed form with the crank angle, and only the two coordinates of the chain 4-8 behind the
  clearance are integrated, by an explicit error-controlled solver (DOPRI5) that takes large steps
  in free flight and short ones through the impacts; with friction in the joint by generalized-alpha
  with an error-controlled step (``solver.exudyn.tree_solver``,
  :func:`tree_solver`): the friction ramp holds an explicit solver
  at ~1e-9 s steps while the journal creeps.  Every scene weftsim describes today with a
  clearance at E is of this kind.
- **rigid-body model** (:mod:`.mechanism`, generalized-alpha) when the scene needs bodies and joints
  for members 1-3.  What forces it (:func:`rigid_body_needs`):
  an ideal joint at E (c = 0: no coordinate moves freely; the rigid-body model then steps
  0.25 deg of crank, :data:`IDEAL_JOINT_STEP_ANGLE`, and never a
  contact time scale).  Friction in the clearance joint does not: the tree's generalized force
  carries the friction force at the contact point and its moments on the rod and, through the
  driving torque, on the rocker (:func:`weftsim.physics.chain.tree_joint_force`).  A clearance or a
  flexible body anywhere in members 1-3 would need the rigid-body model (members 1-3 no longer move
  in closed form); weftsim's scenes have neither yet.

A flexible rapier tape (``[rapier_tape]`` run flexible) rides on the kinematic tree of its linkage with a
massless rapier (:mod:`.tape_tree`); the rigid-body model does not carry it.

``"rigid_body"`` and ``"kinematic_tree"`` stay explicit choices.  :func:`weftsim.exudyn_engine.solve`
runs exactly the model this module names, with the steps it plans (:func:`adaptive`, :func:`step_plan`:
the error-controlled or the fixed step of the rigid-body model).  Plain arithmetic on the scene: this module
imports no Exudyn, so the run-time estimate and the viewer read the plan without building a model.
"""

from __future__ import annotations

import math

from weftsim.input.params import Scene

AUTO = "auto"
# Step of the ideal joint, as crank angle.  The ideal mechanism has no free coordinate: its motion
# is a function of theta = omega t alone, so the error of the ideal curves against the closed form
# (largest difference at a sample / peak, reference mechanism, 2 revolutions) depends on the crank
# angle of the step and not on the speed; measured identical at 400 and 800 rpm: 0.8-1.0e-6 at
# 0.05 deg, 1.5-1.7e-6 at 0.1 deg, 1.0e-5 at 0.25 deg, 6.3e-5 at 0.5 deg (rapier acceleration; the
# torque 4.0e-6 and 1.6e-5).  Truncation of the second-order method grows as ~(omega h)^2.7 here;
# below 0.05 deg the round-off of the constraint reactions (~1/h^2) takes over.  0.5 deg, the
# largest output spacing (a step must end on every sample), stays within the compare tolerance of
# 1e-4 but only by 1.6x; 0.25 deg keeps 10x below it at 5x fewer steps than 0.05 deg.
IDEAL_JOINT_STEP_ANGLE = math.radians(0.25)
# Largest step of the kinematic tree (explicit and implicit): the output sample period / STEPS_PER_SAMPLE (Exudyn's maximum step is endTime /
# numberOfSteps).  With one step per sample (0.5 deg) a light impact could begin and turn back inside one
# free-flight step: the next step end holds a penetration with delta_dot <= 0 and the run fails the
# plausibility guard (2 of 32 ten-revolution runs of four scenes at 400-800 rpm, c = 0.1-0.5 mm, with the
# tolerance perturbed at round-off).  Two per sample: 0 of 64 such runs, 3 % more steps on the reference
# scene (43 067 against 41 846 for 10 revolutions); five per sample also 0 of 32.
STEPS_PER_SAMPLE = 2
# ... and at most this fraction of the time a journal released at rest needs to fall through the clearance
# under gravity, sqrt(2 c / g): in one free-flight step it then falls at most 1 % of c.  At low crank speed
# the half sample is long (0.042 s at 1 rpm) and gravity moves the journal most: a first step of 0.042 s
# from the centred journal ends 99.7 mm deep in the wall; its error estimate (~1e55) asks for a step below
# limits.min_step_s, and Exudyn's DOPRI5 then accepts the rejected step instead (issue 24).  At 300 rpm and
# above the half sample is the smaller bound for every clearance down to 0.01 mm (1.39e-4 s against 1.4e-4 s):
# the loom's scenes take exactly the steps they took before.
GRAVITY_STEP_FRACTION = 0.1
# Largest relative tolerance of the tree with friction.  The friction ramp sticks the journal in phases
# where DOPRI5 steps at its stability limit, and at rtol 1e-6 the error left there broke the energy balance
# (4.5 J, 8e-3 of the largest kinetic energy, in one revolution at mu = 0.15, c = 0.5 mm) and the torque
# maximum (1.1 % off the reference engine); at 1e-8: 0.02 J and 6e-5, and no more steps than at 1e-6
# (the stick phases' steps are set by stability, not accuracy).  A tighter scene value is kept.
# A lubricated joint needs it too: the squeeze film is a damper of ~1e9 N s/m near the wall, DOPRI5 steps
# at its stability limit there, and at rtol 1e-6 the forces at the step ends no longer carried the motion
# (reference scene, 80 mPa s, one revolution: film force 13 % off the reference engine at 220 deg, the energy
# balance failed at 223 deg); at 1e-8: balance 1.7e-4 of the kinetic energy, minimum film ratio within
# 2e-4 of the reference engine, and fewer steps (327 436 against 375 065 up to the failure).
FRICTION_RELATIVE_TOLERANCE = 1e-8


def rigid_body_needs(scene: Scene) -> list[str]:
    """Reasons why ``scene`` needs the rigid-body model (empty: the kinematic tree carries it)."""
    needs = []
    if not scene.joint_f.is_ideal:
        needs.append("clearance at F (the kinematic tree carries the clearance at E only; the rigid-body "
                     "model adds the reusable clearance joint at F)")  # fmt: skip
    if scene.is_ideal:
        needs.append("ideal joint at E (c = 0): no free coordinate, one generalized-alpha step per "
                     "0.25 deg of crank")  # fmt: skip
    return needs


def select_model(scene: Scene) -> tuple[str, str]:
    """(model, reason): the scene key if it names a model, else the automatic choice."""
    model = scene.exudyn_solver.model
    if model != AUTO:
        return model, "scene key solver.exudyn.model"
    needs = rigid_body_needs(scene)
    if needs:
        return "rigid_body", "auto: " + "; ".join(needs)
    return "kinematic_tree", "auto: members 1-3 ideal and rigid, only the chain 4-8 behind the clearance moves freely"


def select_path(scene: Scene) -> dict:
    """``{"model", "method", "reason"}`` of the run :func:`weftsim.exudyn_engine.solve` makes of ``scene``
    (and ``"rapier"``, the tape's verdict, for a scene with a ``[rapier_tape]``)."""
    if scene.rapier_tape is not None:
        from weftsim.model.tape_selection import rigid_scene, tape_check

        check = tape_check(scene)
        if check["model"] == "flexible":  # the tape on the tree of the linkage (weftsim.exudyn_engine.tape_tree)
            from weftsim.model.tape import massless_rapier

            path = select_path(massless_rapier(scene))
            return dict(path, method=path["method"] + f", tape of {scene.rapier_tape.modes} Ritz functions",
                        rapier=check["reason"])
        return dict(select_path(rigid_scene(scene)), rapier=check["reason"])
    s = scene.exudyn_solver
    model, reason = select_model(scene)
    if model == "kinematic_tree":
        from weftsim.exudyn_engine.callbacks import resolve_route

        route = resolve_route(s.callback)
        if tree_solver(scene) == "implicit":
            return {"model": model, "reason": reason,
                    "method": f"generalized-alpha, adaptive step (local error {tree_local_error(scene):g} m at E), "
                              f"{route} callback"}
        return {"model": model, "reason": reason,
                "method": f"{s.explicit_method} rtol {tree_relative_tolerance(scene):g}, {route} callback"}
    if adaptive(scene):
        where = " and ".join(name.upper() for name in scene.loose_joints)  # the rod's pins with a clearance
        method = f"generalized-alpha, adaptive step (local error {s.local_error:g} m at {where})"
    else:
        method = f"generalized-alpha, fixed step h {step_plan(scene)[0]:.3g} s"
    return {"model": model, "method": method, "reason": reason}


def adaptive(scene: Scene) -> bool:
    """True when the step is error-controlled (:mod:`.step_control`): a clearance joint under
    ``step_control = "adaptive"``.  The ideal joint always takes the fixed step of :func:`step_plan`
    (nothing but the prescribed kinematics to follow; :data:`IDEAL_JOINT_STEP_ANGLE`)."""
    return scene.exudyn_solver.step_control == "adaptive" and not scene.is_ideal


def requested_step(scene: Scene) -> float:
    """The fixed step to aim for, s: the scene's, or with the ideal joint :data:`IDEAL_JOINT_STEP_ANGLE`.

    A scene's step is chosen to resolve impacts (about 2e-6 s).  With an ideal joint there is none,
    and such a step only adds round-off: the constraint reactions of generalized-alpha carry an error
    growing as 1/h^2, 9e-5 of the peak driving torque at 2e-6 s against 1e-5 at the ideal step.
    Under ``step_control = "fixed"`` the scene's step is taken as it is, ideal joint or not.
    """
    step = scene.exudyn_solver.step_size
    if scene.is_ideal and scene.exudyn_solver.step_control == "adaptive":
        step = max(step, IDEAL_JOINT_STEP_ANGLE / scene.drive.speed)
    return step


# Round-off floor of the rigid-body model's fixed step.  Generalized-alpha solves the position-level constraints
# scaled by 1/(beta h^2), so the round-off of the coordinates (eps |q|) enters the accelerations and the
# constraint reactions as ~eps |q| / (beta h^2): an absolute error independent of the speed, against peaks
# growing as omega^2, so the share of round-off is ROUNDOFF_GAIN eps / (omega h)^2.  Measured on the loom at
# 600 rpm, 0.01 revolution, peak rapier acceleration against 6571.3 m/s2 (the reference engine at rtol 1e-12):
# h = 1e-7 s: 6571.7; 5e-8: 6572.5 (1.2e-4); 2e-8: 6585.9 (2.2e-3); 1e-8: 6634 (9.6e-3); 5e-9: 6830 (3.9e-2);
# 2e-9: 3.7e4; 1e-9: 1.4e5.  From 2e-8 to 5e-9 the share is 17 eps / (omega h)^2 within 10 %; below, Newton's
# iteration stops resolving the step and it grows faster.  ROUNDOFF_GAIN = 20 bounds it; a fixed step whose
# share exceeds ROUNDOFF_SHARE_LIMIT is refused (600 rpm: below 3.4e-8 s).
ROUNDOFF_GAIN = 20.0
ROUNDOFF_SHARE_LIMIT = 1e-3


def roundoff_floor_step(scene: Scene) -> float:
    """Smallest fixed step of the rigid-body model whose round-off stays within :data:`ROUNDOFF_SHARE_LIMIT` of
    the peak accelerations and reactions, s: sqrt(ROUNDOFF_GAIN eps / ROUNDOFF_SHARE_LIMIT) / omega."""
    return math.sqrt(ROUNDOFF_GAIN * 2.220446049250313e-16 / ROUNDOFF_SHARE_LIMIT) / scene.drive.speed


def roundoff_problem(scene: Scene) -> str | None:
    """One line refusing a fixed step of the rigid-body model below :func:`roundoff_floor_step`, or None."""
    if select_model(scene)[0] != "rigid_body" or adaptive(scene) or scene.drive.speed <= 0.0:
        return None
    h, floor = step_plan(scene)[0], roundoff_floor_step(scene)
    if h >= floor:
        return None
    share = ROUNDOFF_GAIN * 2.220446049250313e-16 / (scene.drive.speed * h) ** 2
    return (f"`solver.exudyn.step_size_s` = {h:.3g} s is below the round-off floor of the rigid-body model at "
            f"{scene.drive.speed * 30.0 / math.pi:g} rpm ({floor:.2g} s): generalized-alpha's accelerations and "
            f"reactions would carry round-off of at least ~{share:.1%} of their peaks, not physics; use a step of at least "
            f"{floor:.2g} s (1e-6 s resolves the impacts to 0.5 %) or step_control = 'adaptive'")


def step_plan(scene: Scene) -> tuple[float, int]:
    """(step size, number of steps): :func:`requested_step` shortened to divide the sample period."""
    omega, t_end = scene.drive.speed, scene.drive.end_time
    sample_dt = scene.output.sample_angle / omega
    per_sample = max(1, math.ceil(sample_dt / requested_step(scene) * (1.0 - 1e-12)))
    n_steps = max(1, round(t_end / (sample_dt / per_sample)))
    return t_end / n_steps, n_steps


def largest_step(scene: Scene) -> float:
    """Largest step of the tree, s: half an output sample, and at most :data:`GRAVITY_STEP_FRACTION` of
    the fall time through the clearance sqrt(2 c / g)."""
    h = scene.output.sample_angle / scene.drive.speed / STEPS_PER_SAMPLE
    g = scene.inertia.gravity
    if g > 0.0:
        h = min(h, GRAVITY_STEP_FRACTION * math.sqrt(2.0 * scene.joint.clearance / g))
    return h


def tree_solver(scene: Scene) -> str:
    """"explicit" or "implicit": the scene key ``solver.exudyn.tree_solver``, or under "auto" implicit
    with friction in the joint (the explicit solver steps at ~1e-9 s while the journal creeps on the
    friction ramp; :mod:`.tree_implicit`) or an oil film (the squeeze film is a damper of ~1e9 N s/m near
    the wall: DOPRI5 at rtol 1e-8 took 513 065 steps for one revolution of the loom at c = 0.02 mm, 80 mPa s,
    26 s; generalized-alpha 2 167 steps, 0.13 s, peaks within 1e-4 of it), and explicit otherwise
    (faster there, docs/performance.md)."""
    choice = scene.exudyn_solver.tree_solver
    if choice != "auto":
        return choice
    return "implicit" if scene.joint.friction_coefficient > 0.0 or scene.joint.is_lubricated else "explicit"


def tree_relative_tolerance(scene: Scene) -> float:
    """The explicit solver's relative tolerance: the scene's, at most :data:`FRICTION_RELATIVE_TOLERANCE`
    with friction in the joint or a lubricated joint."""
    rtol = scene.exudyn_solver.relative_tolerance
    tight = scene.joint.friction_coefficient > 0.0 or scene.joint.is_lubricated
    return min(rtol, FRICTION_RELATIVE_TOLERANCE) if tight else rtol


# The implicit tree's local error with an oil film.  Where the film carries the journal smoothly its steps
# are long, and the minimum film thickness, read at the step ends, is missed between them by O(h^2): loom,
# c = 0.02 mm, 80 mPa s, one revolution, smallest film ratio against the reference engine at rtol 1e-8
# (8.8043): 1.2 % low at 3e-10 m (2 167 steps), 0.28 % at 3e-11, 0.06 % at 3e-12 (7 602 steps, 0.74 s
# against 0.08 s dry).  An impact into the film: the reference scene's start-up (0.1 revolution, c = 0.25 mm,
# a 3 MN squeeze peak) has its torque maximum 1.1 % low at 3e-11 and within 4e-4 of the reference engine at
# rtol 1e-8 at 3e-12 (DOPRI5 at rtol 1e-8: 3e-4).
LUBRICATED_LOCAL_ERROR = 3e-12


def tree_local_error(scene: Scene) -> float:
    """The implicit tree's local error, m: the scene's, at most :data:`LUBRICATED_LOCAL_ERROR` with an oil film."""
    local_error = scene.exudyn_solver.local_error
    return min(local_error, LUBRICATED_LOCAL_ERROR) if scene.joint.is_lubricated else local_error
