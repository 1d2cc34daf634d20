"""``solve`` of the kinematic-tree model (:mod:`.tree`): explicit or implicit solver, channels, failures.

Solver (:func:`tree_solver`): with friction in the joint generalized-alpha with error control and
friction segments (:mod:`.tree_implicit`); otherwise, or under ``solver.exudyn.tree_solver = "explicit"``,
Exudyn's explicit ``solver.exudyn.explicit_method`` (DOPRI5 or ODE23) with
automatic step size, ``relative_tolerance`` (at most :data:`FRICTION_RELATIVE_TOLERANCE` with
friction) and ``absolute_tolerance`` (on the joint
angles, rad, and rates, rad/s), end-of-step accelerations on (else the rapier acceleration
lags a stage), largest step = half an output sample period (:data:`STEPS_PER_SAMPLE`).  Output samples are interpolated
linearly between accepted steps (peaks and statistics use the steps themselves).

Channels, at every accepted step (docs/physics.md section 4 signs):

    a, psi           q0, q0 + q1 - pi;   rapier s, v, a = (d5 d7/d6) (a - a(0), a', a'')
    e, delta, F_N    from a, psi and the closed-form bearing motion
                     (:func:`weftsim.model.dynamics.eccentricity`); F_N = |connector Force|
    torque           1/2 J13' omega^2 + U13' - Q3, Q3 = F_b . dP_b/dtheta + M_b phi' (:mod:`weftsim.model.ideal`;
                     F_b, M_b: force and friction moment on the bearing)
    energies         kinetic 1/2 J13 omega^2 + chain (:func:`~weftsim.model.dynamics.chain_energy`),
                     potential U13 + m4 g z4, contact law.elastic_energy(delta), driving work
                     [1/2 J13 omega^2 + U13]_0^t + integral -Q3 omega dt, dissipated
                     integral (F_N - F_el) delta_dot - F_T v_T dt (damping and friction work,
                     :func:`contact_work` over accepted steps)

Failures as in :mod:`.solver`: the run guards of :mod:`weftsim.checks.guards` after every step,
Exudyn exceptions, non-finite values, a premature stop; :func:`weftsim.checks.guards.vet_result`.
"""

from __future__ import annotations

import math
import time as _time
from typing import TYPE_CHECKING

import exudyn as exu
import numpy as np
from exudyn.itemInterface import SensorNode

from weftsim.joint.contact import make_law
from weftsim.exudyn_engine.sensors import first_nonfinite_row, sample_channels, silence
from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.clearance_joint import register_post_step
from weftsim.exudyn_engine.tree import POWER_JOINTS, TreeModel, build_tree
from weftsim.exudyn_engine.selection import (  # noqa: F401 (re-exported: the tree's plan lives in selection)
    FRICTION_RELATIVE_TOLERANCE,
    GRAVITY_STEP_FRACTION,
    LUBRICATED_LOCAL_ERROR,
    STEPS_PER_SAMPLE,
    largest_step,
    tree_local_error,
    tree_relative_tolerance,
    tree_solver,
)
from weftsim.exudyn_engine.tape_tree import add_tape, tape_sensors, with_tape
from weftsim.exudyn_engine.tree_implicit import ImplicitTree
from weftsim.exudyn_engine.step_control import failure_reason as implicit_failure
from weftsim.checks.guards import RunGuard, failure_message, non_finite_breach, raised_min_step
from weftsim.input.params import Scene
from weftsim.model.dynamics import NUMPY, ChainConstants, chain_energy, eccentricity, initial_state
from weftsim.model.ideal import crank_side_inertia, crank_side_potential
from weftsim.model.tape import massless_rapier
from weftsim.post.results import RunResult, angle_grid, empty_channels

if TYPE_CHECKING:
    from collections.abc import Callable

OVT = exu.OutputVariableType
EXPLICIT_METHODS = {"DOPRI5": exu.DynamicSolverType.DOPRI5, "ODE23": exu.DynamicSolverType.ODE23}
_PROGRESS_EVERY = 0.001  # every 0.1 % of the run: a long run shows its first line soon (issue 16)
END_OF_STEP_ACCELERATIONS = False
RECORD_COLUMNS = 11  # TreeModel.bearing_force: t, F_b,x, F_b,y, F_N, M_b, F_T v_T, D'_lub, U_a, v_T, W3', D'


def check_tree_settings(scene: Scene) -> str | None:
    """Message naming the first setting the kinematic-tree model cannot run with, or None."""
    s = scene.exudyn_solver
    if not scene.joint_f.is_ideal:
        return ("the 'kinematic_tree' Exudyn model carries the clearance at E only, and this scene has one at F "
                "(joint_f); use `solver.exudyn.model` = 'auto' or 'rigid_body' (it adds the clearance joint at F)")
    if scene.joint.is_ideal:
        return ("the 'kinematic_tree' Exudyn model needs a clearance joint (with an ideal joint nothing moves "
                "freely); use `solver.exudyn.model` = 'rigid_body' or the reference engine")  # fmt: skip
    routes = ("auto",) + callbacks.ROUTES
    if s.callback not in routes:
        return (f"the 'kinematic_tree' Exudyn model has the callback routes {routes}, got {s.callback!r}; "
                "use `solver.exudyn.model` = 'rigid_body' for it")  # fmt: skip
    if s.tree_solver not in ("auto", "explicit", "implicit"):
        return f"`solver.exudyn.tree_solver` must be one of 'auto', 'explicit', 'implicit', got {s.tree_solver!r}"
    if s.explicit_method not in EXPLICIT_METHODS:
        return f"`solver.exudyn.explicit_method` must be one of {tuple(EXPLICIT_METHODS)}, got {s.explicit_method!r}"
    for name in ("relative_tolerance", "absolute_tolerance"):
        value = getattr(s, name)
        if not (value > 0.0 and math.isfinite(value)):
            return f"`solver.exudyn.{name}` must be > 0, got {value}"
    return None


def step_advice(scene: Scene, implicit: bool) -> str:
    """What to try after a step collapse of the kinematic tree, naming its own solver keys (the guard's hint)."""
    if implicit:
        return (f"a looser solver.exudyn.local_error_m (now {scene.exudyn_solver.local_error:.3g} m) or "
                "solver.exudyn.tree_solver = 'explicit'")
    other = next(name for name in EXPLICIT_METHODS if name != scene.exudyn_solver.explicit_method)
    return (f"a looser solver.exudyn.relative_tolerance / absolute_tolerance, solver.exudyn.explicit_method = "
            f"{other!r}, or solver.exudyn.tree_solver = 'implicit'")


def power_sums(scene: Scene) -> bool:
    """True when the implicit tree integrates W3 and D by :func:`step_trapezoids` instead of the power joints: dry
    friction at E without a tape (generalized-alpha at :data:`~weftsim.exudyn_engine.tree_implicit.SPECTRAL_RADIUS`
    1 gives the power joints exactly these sums, without their two columns of Newton's numerical Jacobian)."""
    return (scene.joint.friction_coefficient > 0.0 and not scene.joint.is_lubricated and scene.rapier_tape is None
            and tree_solver(scene) == "implicit")


def step_trapezoids(power: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Running trapezoidal sum of ``power`` over the accepted steps' ends ``t``, J.

    What generalized-alpha at spectral radius 1 (alpha_m = alpha_f = 1/2, gamma = 1/2) makes of a power joint
    q'' = P, unit mass, whose force does not depend on q: its algorithmic accelerations obey
    a[n] + a[n+1] = P[n] + P[n+1], so q'[n+1] - q'[n] = h (a[n] + a[n+1]) / 2 = h (P[n] + P[n+1]) / 2, whatever
    the starting acceleration.  P at the converged states is the callback's (its stash at each accepted step).
    """
    out = np.zeros_like(power)
    if power.size > 1:
        out[1:] = np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))
    return out


def contact_work(y: np.ndarray, t: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Running integral of a contact power y (0 in free flight) over the stored steps, J.

    In contact the steps (~15 us) are not short against the contact oscillation (~0.15 ms): a
    trapezoid loses (h w)^2 / 12 of each oscillation, which accumulated to 0.17 J per revolution at
    c = 0.5 mm (rtol 1e-6) and failed the energy guard after ~30 revolutions.  So a step whose
    neighbour is in contact too is integrated with the quadratic through three step ends (the
    step's two and the next one's, or the previous one's for the last step; weights of the
    non-uniform Simpson rule, error O(h^4)):

        int_{x0}^{x1} = h1/6 [ (3H - h1)/H y0 + (3H - 2 h1)/h2 y1 - h1^2/(H h2) y2 ],
        h1 = x1 - x0, h2 = x2 - x1, H = h1 + h2.

    A step where the contact starts or ends: y is 0 from the crossing of delta = 0 (linear in the
    step, s = delta0 / (delta0 - delta1), as the onset tracking) to the free end, so only the part
    in contact counts, 1/2 y_in (fraction in contact) h.  Other steps: trapezoids.
    """
    n = len(y)
    out = np.zeros_like(y)
    if n < 2:
        return out
    h = np.diff(t)
    d0, d1 = delta[:-1], delta[1:]
    area = 0.5 * (y[1:] + y[:-1]) * h
    inside = delta > 0.0
    if n >= 3:
        # forward stencil (i, i+1, i+2) for steps 0..n-3, backward (i-1, i, i+1) for the last one
        h1, h2 = h[:-1], h[1:]
        big = h1 + h2
        fwd = inside[:-2] & inside[1:-1] & inside[2:]
        fw = (h1 / 6.0) * ((3.0 * big - h1) / big * y[:-2] + (3.0 * big - 2.0 * h1) / h2 * y[1:-1]
                           - h1 * h1 / (big * h2) * y[2:])  # fmt: skip
        area[:-1][fwd] = fw[fwd]
        if inside[-3] and inside[-2] and inside[-1]:  # mirror of the forward rule on the last step
            g1, g2 = h[-1], h[-2]
            gb = g1 + g2
            area[-1] = (g1 / 6.0) * ((3.0 * gb - g1) / gb * y[-1] + (3.0 * gb - 2.0 * g1) / g2 * y[-2]
                                     - g1 * g1 / (gb * g2) * y[-3])  # fmt: skip
    onset = (d0 <= 0.0) & (d1 > 0.0)
    separation = (d0 > 0.0) & (d1 <= 0.0)
    crossing = onset | separation
    s = np.zeros_like(h)
    s[crossing] = d0[crossing] / (d0[crossing] - d1[crossing])
    area[onset] = 0.5 * y[1:][onset] * (1.0 - s[onset]) * h[onset]
    area[separation] = 0.5 * y[:-1][separation] * s[separation] * h[separation]
    out[1:] = np.cumsum(area)
    return out


def worn_channels(scene: Scene, t: np.ndarray, a: np.ndarray, psi: np.ndarray, da: np.ndarray,
                  dpsi: np.ndarray) -> tuple[np.ndarray, ...]:
    """(delta, delta_dot, F_el, U_el) of a worn joint E at the tree's steps: at the local clearance
    c0 + h_b + h_j along e (:func:`weftsim.physics.worn_rows.worn_contact_rows`), delta_dot = e_dot . n - dc/dt."""
    from weftsim.physics.worn_rows import worn_contact_rows
    from weftsim.model.dynamics import pack_parameters

    states = np.ascontiguousarray(np.column_stack([a, psi, da, dpsi]), dtype=float)
    out = np.zeros((t.size, 5))
    worn_contact_rows(pack_parameters(scene), np.ascontiguousarray(t, dtype=float), states, out)
    return out[:, 1], out[:, 2], out[:, 3], out[:, 4]


# Exudyn's explicit step control takes the RMS of the scaled local errors over all ODE2 coordinates and their
# rates: the power joints (integrators of W3 and D, :data:`weftsim.exudyn_engine.tree.POWER_JOINTS`) double the
# entries, and, their own errors being far smaller, dilute the motion's error by sqrt(2 / (2 + POWER_JOINTS)).
# Probe (harmonic 2-DOF ODE2 node, DOPRI5 at rtol 1e-6): 321 steps; 2 extra coordinates with zero error 297
# (whatever their size), 6 extra 276; 2 extra at both tolerances x this share 319.  Without it the reference
# scene at 400 rpm took 4 008 steps a revolution instead of 4 254 and its later-impact extrema moved away from
# the converged reference engine (rtol 1e-11): torque max 0.08 -> 0.97 %, at 800 rpm torque min 0.36 -> 3.4 %,
# acceleration min 0.25 -> 1.75 %.  The explicit tree's tolerances are multiplied by it, so the motion keeps the
# error control it had before the power joints (4 220 steps; 0.06 %, 0.73 %, 0.49 %).
MOTION_SHARE = math.sqrt(2.0 / (2.0 + POWER_JOINTS))


def tree_settings(scene: Scene, tape_coordinates: int = 0) -> exu.SimulationSettings:
    """Explicit solver with automatic step size; no files, no console output.  The tolerances are the scene's
    times :data:`MOTION_SHARE`: the explicit tree carries the power joints (:func:`solve_tree`).  With a
    flexible tape's ``tape_coordinates`` (its Ritz coordinates, motion too) the share is
    sqrt((2 + n) / (2 + n + POWER_JOINTS))."""
    s = scene.exudyn_solver
    omega, t_end = scene.drive.speed, scene.drive.end_time
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.solverType = EXPLICIT_METHODS[s.explicit_method]
    ti.endTime = t_end
    ti.numberOfSteps = STEPS_PER_SAMPLE * max(1, math.ceil(t_end / (scene.output.sample_angle / omega) * (1.0 - 1e-12)))
    ti.numberOfSteps = max(ti.numberOfSteps, math.ceil(t_end / largest_step(scene) * (1.0 - 1e-12)))
    ti.automaticStepSize = True
    motion = 2 + tape_coordinates
    share = math.sqrt(motion / (motion + POWER_JOINTS))
    ti.relativeTolerance = tree_relative_tolerance(scene) * share
    ti.absoluteTolerance = s.absolute_tolerance * share
    ti.minimumStepSize = scene.limits.min_step
    ti.explicit.computeEndOfStepAccelerations = END_OF_STEP_ACCELERATIONS
    silence(ss)
    return ss


def tree_states(data: dict, n: int) -> tuple[np.ndarray, ...]:
    """(t, states (n, 4) [a, psi, a', psi'], F_N, v_T) of the first ``n`` stored steps (:func:`solve_tree`)."""
    q, q_t, force = (np.asarray(data[k])[:n] for k in ("q", "q_t", "force"))
    states = np.zeros((n, 4))
    if n:
        states[:, 0], states[:, 1] = q[:, 1], q[:, 1] + q[:, 2] - math.pi
        states[:, 2], states[:, 3] = q_t[:, 1], q_t[:, 1] + q_t[:, 2]
        return q[:, 0].copy(), states, force[:, 3].copy(), force[:, 8].copy()
    return np.zeros(0), states, np.zeros(0), np.zeros(0)


def crank_motions(scene: Scene, t: np.ndarray) -> tuple:
    """(theta, theta_dot, theta_ddot) at the times ``t`` and (theta, theta_dot) at 0 of the scene's drive law
    (:func:`weftsim.physics.chain.crank_motion`, the one definition): omega t, omega, 0 at constant speed."""
    omega = scene.drive.speed
    if scene.drive.law == "constant":
        return omega * t, omega, 0.0, 0.0, omega
    from weftsim.physics.chain import crank_motion
    from weftsim.model.dynamics import pack_parameters

    prm = pack_parameters(scene)
    motion = np.array([crank_motion(prm, float(x)) for x in t]).reshape(-1, 3)
    start = crank_motion(prm, 0.0)
    return motion[:, 0], motion[:, 1], motion[:, 2], start[0], start[1]


def tree_channels(model: TreeModel, data: dict) -> dict[str, np.ndarray]:
    """All channels at the stored steps from the sensors' data (rows cut to a common length)."""
    scene = model.scene
    n = min(len(v) for v in data.values())
    q, q_t, q_tt, force = (data[k][:n] for k in ("q", "q_t", "q_tt", "force"))
    if n and np.any(force[:, 0] != q[:, 0]):
        raise RuntimeError("kinematic tree: the recorded contact forces are not at the sensors' times")
    t = q[:, 0]
    a, psi = q[:, 1], q[:, 1] + q[:, 2] - math.pi
    da, dpsi = q_t[:, 1], q_t[:, 1] + q_t[:, 2]
    p = ChainConstants.from_scene(scene)
    omega = p.omega
    ecc_y, ecc_z, v_y, v_z, dphi, db_y, db_z = eccentricity(NUMPY, p, t, a, psi, da, dpsi)
    length = np.hypot(ecc_y, ecc_z)
    delta = length - p.clearance
    rate = np.where(length > 0.0, (ecc_y * v_y + ecc_z * v_z) / np.where(length > 0.0, length, 1.0), 0.0)
    f_b = force[:, 1:3]  # F_N n - F_T t, the force on the bearing
    f_n, m_b, friction_power = force[:, 3], force[:, 4], force[:, 5]
    q3 = f_b[:, 0] * db_y + f_b[:, 1] * db_z + m_b * dphi
    theta, omega, acceleration, theta0, omega0 = crank_motions(scene, t)  # omega t, omega, 0 at constant speed
    j13, dj13 = crank_side_inertia(theta, scene)
    u13, du13 = crank_side_potential(theta, scene)
    j13_0, _ = crank_side_inertia(theta0, scene)
    u13_0, _ = crank_side_potential(theta0, scene)
    kin48, pot48 = chain_energy(p, a, psi, da, dpsi)
    law = make_law(scene.joint)
    inside = delta > 0.0
    f_el = np.zeros(n)
    energy = np.zeros(n)
    f_el[inside] = law.elastic_force(delta[inside])
    energy[inside] = law.elastic_energy(delta[inside])
    radial_rate = rate  # e_dot . n: F_N works along it (delta_dot of a worn joint also holds -dc/dt)
    if scene.joint.is_worn:  # the local clearance the callback saw (weftsim.physics.worn_rows), as the reference's
        delta, rate, f_el, energy = worn_channels(scene, t, a, psi, da, dpsi)
    # A lubricated joint: the film and boundary friction dissipate at every step (the quadratic rule of
    # contact_work over all steps: the squeeze film's power peaks within a few steps, where trapezoids
    # left 1 % of the kinetic energy in a revolution at 80 mPa s), the asperities store U_a.
    lubricated_work = np.zeros(n)
    loaded = delta  # where the joint carries load: in contact, or at every step when lubricated
    if scene.joint.is_lubricated and n > 1:
        loaded = np.ones(n)
        lubricated_work = contact_work(force[:, 6], t, np.ones(n))
        energy = energy + force[:, 7]
    if q_t.shape[1] > 3:  # the power joints (build_tree(powers=True)): W3 and D integrated with the motion
        drawn, dissipated = q_t[:, 3] - q_t[0, 3], q_t[:, 4] - q_t[0, 4]
    elif power_sums(scene):  # generalized-alpha's own rule for them, at the accepted steps' ends
        drawn, dissipated = step_trapezoids(force[:, 9], t), step_trapezoids(force[:, 10], t)
    else:  # quadrature over the steps (the implicit tree with an oil film)
        drawn = contact_work(-q3 * omega, t, loaded)
        # the tree_joint_force's D': F_N (delta_dot + dc/dt) - F_el delta_dot - F_T v_T
        dissipated = contact_work((f_n - f_el) * rate + f_n * (radial_rate - rate) - friction_power, t, delta) \
            + lubricated_work
    hist = model.tracker.history()
    row = np.clip(np.searchsorted(hist["time"], t * (1.0 + 1e-12), side="right") - 1, 0, len(hist["time"]) - 1)
    ratio = scene.geometry.rapier_ratio
    kin13 = 0.5 * j13 * omega**2
    # The film channels and the joint's load from the kernel at the tree's states (weftsim.joint.lubrication,
    # weftsim.joint.load).
    from weftsim.joint.load import joint_force_table
    from weftsim.model.dynamics import pack_parameters

    prm = pack_parameters(scene)
    states = np.zeros((n, 6))
    states[:, 0], states[:, 1], states[:, 2], states[:, 3] = a, psi, da, dpsi
    lubricated = joint_force_table(scene, prm, t, states, {"contact_force_N": f_n})
    if scene.joint.is_lubricated:
        from weftsim.joint.lubrication import lubrication_table

        lubricated |= lubrication_table(scene, prm, t, states)[0]
    return lubricated | {
        "time_s": t,
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": ratio * (a - initial_state(scene)[0]),
        "rapier_velocity_m_s": ratio * da,
        "rapier_acceleration_m_s2": ratio * q_tt[:, 1],
        "driving_torque_Nm": 0.5 * dj13 * omega**2 + du13 - q3 + (j13 * acceleration if scene.drive.law != "constant"
                                                                  else 0.0),
        "contact_force_N": f_n,
        "penetration_m": delta,
        "eccentricity_y_m": ecc_y,
        "eccentricity_z_m": ecc_z,
        "impact_velocity_m_s": hist["impact_velocity"][row],
        "in_contact": hist["in_contact"][row],
        "kinetic_energy_J": kin13 + kin48,
        "potential_energy_J": u13 + pot48,
        "contact_energy_J": energy,
        "driving_work_J": kin13 + u13 - (0.5 * float(j13_0) * omega0**2 + float(u13_0)) + drawn,
        "dissipated_energy_J": dissipated,
        "penetration_rate_m_s": rate,
    }


def solve_tree(scene: Scene, progress: Callable[[float], None] | None = None, callback: str | None = None,
               observe: Callable[..., None] | None = None) -> RunResult:
    """Simulate a scene with the kinematic-tree model (settings checked by the caller).

    ``observe``: called once after the run as ``observe(t, states, f_n, v_t)`` with the rows behind
    ``result.steps`` (times (n,) s; states (n, 4) [a, psi, a', psi']; the callback's normal force F_N (n,) N
    and sliding velocity v_T (n,) m/s, 0 out of contact): the contact channels the wear's Archard integral
    reads (:mod:`weftsim.wear.engines`).
    """
    wall0 = _time.perf_counter()
    omega, t_end = scene.drive.speed, scene.drive.end_time
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    implicit = tree_solver(scene) == "implicit"
    # The power joints (W3 and D integrated with the motion) on the explicit tree.  On the implicit one with dry
    # friction the contact_work quadrature drifted 0.042 J a revolution on the loom at c = 0.1 mm (the energy
    # guard's 1 % after ~230 revolutions) and the power joints cost 40 % more CPU time (two more columns of the
    # numerical Jacobian); their own rule, the trapezoid at the accepted steps' ends (power_sums), gives their
    # balance without them.  With an oil film they changed nothing (3.9e-3 and 4.3e-3 J in 3 revolutions) and
    # cost 47 %: the quadrature stays.
    powers = not implicit
    # A flexible rapier tape: the tree of the linkage with a massless rapier, the tape and head on its wheel
    # (:mod:`.tape_tree`; its damping enters the power joint of D, so it needs the power joints).
    tape_scene = scene.rapier_tape is not None
    linkage = massless_rapier(scene) if tape_scene else scene
    powers = powers or tape_scene
    model = build_tree(mbs, linkage, scene.exudyn_solver.callback if callback is None else callback, powers=powers)
    store = {"storeInternal": True, "writeToFile": False}
    sensors = {
        "q": mbs.AddSensor(SensorNode(nodeNumber=model.node, outputVariableType=OVT.Coordinates, **store)),
        "q_t": mbs.AddSensor(SensorNode(nodeNumber=model.node, outputVariableType=OVT.Coordinates_t, **store)),
        "q_tt": mbs.AddSensor(SensorNode(nodeNumber=model.node, outputVariableType=OVT.Coordinates_tt, **store)),
    }
    tape = add_tape(mbs, scene, model.node) if tape_scene else None
    if tape is not None:
        sensors |= tape_sensors(mbs, tape, store)
    guard = RunGuard(scene, step_advice=step_advice(scene, implicit))
    breach = []
    state = {"t": 0.0, "next_report": _PROGRESS_EVERY, "min_step": math.inf}

    last_cut = t_end * (1.0 - 1e-12)  # the last step is cut to land on the end time
    tracker = model.tracker

    def post_step(mbs, t):
        model.accept(mbs, t)
        if t <= 0.0:  # Exudyn also calls this once at t = 0: not a step
            return True
        h = t - state["t"]
        state["t"] = t
        if t < last_cut:
            if h < state["min_step"]:
                state["min_step"] = h
        else:
            h = None
        if progress is not None and t >= state["next_report"] * t_end:
            progress(min(1.0, t / t_end))
            state["next_report"] = math.floor(t / t_end / _PROGRESS_EVERY + 1.0) * _PROGRESS_EVERY
        found = guard.check(penetration=tracker.delta, step_size=h,
                            floor_fails=not implicit)  # the explicit solvers go on at the floor, unchecked
        if found is not None:
            breach.append(found)
            return False
        return True

    solver: exu.MainSolverImplicitSecondOrder | exu.MainSolverExplicit
    if implicit:
        register_post_step(mbs, post_step)  # first: the step controller's hook plans the next step after it
        solver = exu.MainSolverImplicitSecondOrder()
        stepper = ImplicitTree(mbs, solver, model, scene)
        stepper.install()
    else:
        mbs.SetPostStepUserFunction(post_step)  # the one hook, without register_post_step's dispatcher
        solver = exu.MainSolverExplicit()
    mbs.Assemble()
    if progress is not None:
        progress(0.0)
    settings = tree_settings(scene, tape.modes if tape is not None else 0)
    if implicit:
        stepper.settings(settings)
    status, message, kind = "success", "", None
    wall_solve = _time.perf_counter()
    try:
        if not solver.SolveSystem(mbs, settings):  # type: ignore[call-arg, misc]  # exudyn stub: SolveSystem lacks self
            if implicit:
                status = "failed"
                kind, message = implicit_failure(solver, scene)
            else:
                reason = solver.GetErrorString()  # type: ignore[misc]  # exudyn stub: GetErrorString lacks self
                status, kind, message = "failed", "solver", reason or "the explicit solver stopped"
    except exu.ExudynError as exc:
        text = str(exc).strip().splitlines()
        last = text[-1].split(" [Python file ")[0] if text else ""
        status, message = "failed", f"{type(exc).__name__}: {last}"
        kind = "non_finite" if isinstance(exc, exu.SolverError) else "model" if isinstance(exc, exu.ModelError) else "solver"
    wall_solve = _time.perf_counter() - wall_solve
    data = {k: np.asarray(mbs.GetSensorStoredData(v)) for k, v in sensors.items()}  # the stub says ArrayLike
    data["force"] = np.array(model.bearing_force).reshape(-1, RECORD_COLUMNS)
    steps = tree_channels(model, data) if min(len(v) for v in data.values()) else empty_channels()
    if tape is not None:
        steps = with_tape(steps, tape, scene, data) if len(steps["time_s"]) else empty_channels(scene=scene)
    if observe is not None:
        observe(*tree_states(data, len(steps["time_s"])))
    bad = first_nonfinite_row(steps)
    if bad is not None:
        steps = {k: v[:bad] for k, v in steps.items()}
        if status == "success":
            found = non_finite_breach("non-finite values (NaN or inf) in the results (explicit solvers do not stop on NaN)")
            status, message, kind = "failed", found.what, found.kind
    t_last = float(steps["time_s"][-1]) if len(steps["time_s"]) else 0.0
    floor = raised_min_step(scene) if "step-size collapse" in message else ""  # the step reduction's floor
    if implicit:
        hint = (f"try {floor}a smaller `solver.exudyn.local_error_m`, `solver.exudyn.tree_solver` = 'explicit', "
                "or the reference engine")  # fmt: skip
    else:
        hint = ("try a tighter `solver.exudyn.relative_tolerance`, the 'rigid_body' model, or the reference engine")
    if breach and (status == "success" or kind is None):
        status, kind = "failed", breach[0].kind
        message = failure_message("Exudyn engine (kinematic_tree)", t_last, omega, breach[0].what, breach[0].hint)
    elif status == "failed":
        message = failure_message("Exudyn engine (kinematic_tree)", t_last, omega, message, hint)
    elif t_end - t_last > 1e-9 * t_end:
        status, kind = "failed", "stopped"
        message = f"Exudyn stopped at t = {t_last:.6g} s before the end time {t_end:.6g} s; {hint}"
    samples = sample_channels(steps, angle_grid(t_end, omega, scene.output.sample_angle))
    it = solver.it
    n_done = max(len(steps["time_s"]) - 1, 0)
    if implicit:
        method = {"method": "generalized_alpha", "local_error_m": tree_local_error(scene),
                  "rejected_steps": int(it.rejectedModifiedNewtonSteps), "newton_iterations": int(it.newtonStepsCount),
                  "jacobian_evaluations": int(it.newtonJacobiCount), **stepper.counters()}  # fmt: skip
    else:
        method = {"method": scene.exudyn_solver.explicit_method, "relative_tolerance": tree_relative_tolerance(scene),
                  "rejected_steps": int(it.rejectedAutomaticStepSizeSteps)}  # fmt: skip
    stats = {
        **method,
        "model": "kinematic_tree",
        "steps": n_done,
        "min_step_s": state["min_step"],
        "callback": model.route,
        "callback_calls": int(model.callback_calls[0]),
        **model.tracker.counters(),  # contact_events, nonpositive_onsets, separations, missed_*
        "solve_time_s": wall_solve,
        "wall_time_s": _time.perf_counter() - wall0,
    }
    if kind is not None:
        stats["failure"] = kind
    stats["time_per_step_us"] = 1e6 * wall_solve / max(n_done, 1)
    if progress is not None:
        progress(1.0)
    # vetted once, outside the engines, by weftsim.api.simulate (weftsim.checks.guards.vet_result)
    return RunResult(scene, "exudyn", status, message, samples, steps, stats,
                     {"first_contact_time_s": model.tracker.first_contact_time, **model.tracker.counters()})
