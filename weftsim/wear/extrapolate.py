"""Cycle extrapolation of the wear at the clearance joints E and F (docs/wear.md section 3).

Every loose joint of the scene wears (:func:`wearing_joints`: E, F, or E and F), each with its own
``[joint_*.wear]`` numbers and profiles, simulated together in one run; the update rule below holds
for each joint's own effective clearance and the interval is the smallest the joints allow.

One **update**: simulate the mechanism on the current worn geometry for ``settle_revolutions``
(not counted: the start from the centred journal) plus ``revolutions_per_update`` steady
revolutions, take the Archard wear per steady revolution (:mod:`.archard`), and extrapolate it
over N revolutions, as Flores (Mech. Mach. Theory 44, 2009) and Mukras et al. (Wear 268, 2010)
do.  N adapts: the effective clearance c_eff = c0 + max h_b + max h_j may grow by at most the
fraction ``max_clearance_change`` of its value per update,

    N = f c_eff / (max dh_b + max dh_j)        (dh per revolution; an upper bound of dc_eff/rev),

cut to the hours left.  Each update is one :class:`~weftsim.wear.updates.Update` (the data model of
:mod:`weftsim.wear.updates`, re-exported here): the state a run resumes from.

The prediction ends early, with one line saying why, where the worn geometry leaves the model
(:func:`geometric_limit`): the effective clearance reaches the journal radius (the bound a scene
puts on ``joint_e.clearance_mm``; the journal would be worn through), or a worn wall's slope reaches
:data:`MAX_WALL_SLOPE` (the small-wear geometry of docs/wear.md section 2).  The update that would
cross it extrapolates only up to it (:func:`predict`); nothing is simulated beyond.  Wear so fast
that an update's own revolutions grow the clearance by more than ``max_clearance_change`` cannot be
extrapolated at all and is refused (:class:`~weftsim.errors.WearError`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from weftsim.joint.load import joint_load
from weftsim.post.analysis import channel_statistics, time_weights
from weftsim.errors import WearError
from weftsim.wear.archard import run_wear
from weftsim.wear.updates import (  # noqa: F401 - the data model of a prediction, used here and re-exported
    SECONDS_PER_HOUR, JointWear, Update, _with_parts, advance, advance_update, effective_clearance, joint_of,
    limit_hours, wearing_joints,
)  # fmt: skip

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from weftsim.input.params import Scene
    from weftsim.wear.archard import RunWear

# Film ratio h_min / sigma below which a lubricated joint runs mixed (asperities carry part of the load;
# above ~3 the film separates the surfaces: hydrodynamic).  The response's ``mixed_fraction`` is the time
# share of the steady cycle below it.
MIXED_FILM_RATIO = 3.0
# Solver tolerance of the runs on a worn geometry: at the reference engine's default (rtol 1e-5) the
# separation search misses a few exits of the journal from the worn part of the wall and the run's
# contact-history check fails (measured: 4 steps down to -1.2e-7 m on the reference loom's sixth
# update); at 1e-6 every update of the 300-800 rpm study passed at the same cost (0.11 s for 5
# revolutions).  An update that still fails (seen at 100 rpm: one step at -5e-7 m) is run once more
# with RETRY_*; wear.csv records the rtol each update ran at (solver_rtol).
WORN_RTOL, WORN_ATOL = 1e-6, 1e-9
RETRY_RTOL, RETRY_ATOL, RETRY_MAX_STEP = 1e-8, 1e-11, math.radians(0.1)
# Largest slope dh/(R dpsi) of a worn wall the model takes: it treats the worn wall's normal as the
# eccentricity direction n, off by the slope angle alpha.  At 0.1 rad the force along n is off by
# 1 - cos(alpha) = 0.5 % and the neglected tangential part of the wall's force is 10 % of F_N, the
# size of a dry friction force the joint model otherwise counts; the reference loom at c_eff = 0.36 mm
# has 0.012 rad (docs/wear.md section 2).
MAX_WALL_SLOPE = 0.1
# Longest prediction: 1e6 h are 114 years of continuous running, beyond any machine's life (a loom
# runs some 1e5 h); longer requests are typing errors (1e308) that the extrapolation cannot serve.
MAX_HOURS = 1e6


class WearInterrupted(Exception):
    """A stop was asked for (Ctrl-C, SIGTERM) while an update was being simulated: the update is dropped."""


class UpdateFailed(WearError):
    """The simulation of an update failed at every tolerance and integrator tried (a hard cycle)."""


# A hard cycle (an update whose simulation fails at every tolerance and integrator) is one chaotic event of
# one geometry: the prediction backs off, halving the previous update's N (a slightly different geometry,
# still within max_clearance_change), up to MAX_BACKOFFS times in a row before it gives up.
MAX_BACKOFFS = 4
IMPLICIT_METHOD = "numba_DOP853_RODAS4"  # the last attempt: DOP853 in free flight, RODAS4 in contact



def wall_slope(profile: np.ndarray, radius: float) -> float:
    """Largest slope |dh/dpsi| / R of a periodic worn-depth table (central differences), rad."""
    if profile.size < 3:
        return 0.0
    dpsi = 2.0 * math.pi / profile.size
    return float(np.max(np.abs(np.roll(profile, -1) - np.roll(profile, 1)))) / (2.0 * dpsi * radius)


def geometric_limit(scene: Scene, bearing: np.ndarray, journal: np.ndarray, joint: str = "e") -> str | None:
    """Why the worn geometry (bearing, journal; m) of ``joint`` is beyond the model, as one clause, or None."""
    table = f"joint_{joint}"
    pin = joint_of(scene, joint)
    c_eff = effective_clearance(pin.clearance, bearing, journal)
    if c_eff >= pin.journal_radius * (1.0 - 1e-9):
        return (f"the effective clearance at {table[-1].upper()} reaches the journal radius "
                f"{pin.journal_radius * 1e3:g} mm (the bound of {table}.clearance_mm; the journal would be worn "
                "through)")
    slope = max(wall_slope(bearing, pin.bearing_radius), wall_slope(journal, pin.journal_radius))
    if slope >= MAX_WALL_SLOPE * (1.0 - 1e-9):
        return (f"a worn wall's slope at {table[-1].upper()} reaches {MAX_WALL_SLOPE:g} rad (the small-wear "
                "geometry the contact model assumes, docs/wear.md section 2)")
    return None


def state_limit(scene: Scene, update: Update) -> str | None:
    """The first :func:`geometric_limit` any joint of ``update``'s geometry is beyond (E before F), or None."""
    for part in update.worn():
        why = geometric_limit(scene, part.bearing, part.journal, part.joint)
        if why is not None:
            return why
    return None


def ended_by_limit(scene: Scene, updates: Sequence[Update]) -> str | None:
    """The :func:`geometric_limit` that ended the prediction ``updates`` at its last update, or None."""
    if not updates or updates[-1].step_revolutions == 0.0:
        return None
    return state_limit(scene, advance_update(updates[-1], scene))


def _cut_to_limit(update: Update, scene: Scene) -> Update:
    """``update`` with its revolutions cut so the geometry just reaches :func:`geometric_limit` (unchanged if
    its whole extrapolation stays inside)."""
    if state_limit(scene, advance_update(update, scene)) is None:
        return update
    inside, outside = 0.0, update.step_revolutions
    for _ in range(60):  # bisection to a relative 1e-18 of N: the limit is reached to round-off
        middle = 0.5 * (inside + outside)
        if state_limit(scene, advance_update(replace(update, step_revolutions=middle), scene)) is None:
            inside = middle
        else:
            outside = middle
    return replace(update, step_revolutions=outside)


def _worn_joint(joint, bearing: np.ndarray, journal: np.ndarray, film: tuple[float, float] | None = None):
    worn = bool(np.any(bearing) or np.any(journal))
    joint = replace(joint, bearing_wear=tuple(map(float, bearing)) if worn else (),
                    journal_wear=tuple(map(float, journal)) if worn else ())
    if worn and joint.lubrication is not None:
        joint = replace(joint, lubrication=worn_film(joint, effective_clearance(joint.clearance, bearing, journal),
                                                     film))
    return joint


def run_in_roughness(wear, sigma0: float, depth: float) -> float:
    """The combined RMS roughness (m) after the surfaces have worn ``depth`` (m) where they touch (running-in).

    sigma(h) = sigma_ss + (sigma0 - sigma_ss) exp(-h / h_r): the asperities' peaks are worn off first and the
    roughness falls towards its run-in value sigma_ss (``run_in_roughness_um``) over a worn depth of a few h_r
    (``run_in_depth_um``), the exponential transient of running-in models (Queener, Smith and Mitchell, Wear 8,
    1965; Hu, Li and Tonder, J. Tribol. 113, 1991; reviewed by Khonsari, Ghatrehsamani and Akbarzadeh, Wear
    474, 2021).  Without ``run_in_roughness_um`` the roughness stays sigma0.
    """
    if wear.run_in_roughness is None:
        return sigma0
    return wear.run_in_roughness + (sigma0 - wear.run_in_roughness) * math.exp(-depth / wear.run_in_depth)


def worn_film(joint, clearance: float, film: tuple[float, float] | None = None):
    """The lubrication of a worn ``joint`` whose effective clearance is ``clearance`` (m): the roughness run in
    by the worn depth c_eff - c0 (:func:`run_in_roughness`) and, for a joint given an oil (the viscosity from
    the bearing's heat balance, ``film_temperature`` set), the viscosity at the film temperature of the heat
    balance at that clearance (:func:`weftsim.joint.heat.with_film_temperature`; ``film``: its (mean load N,
    journal speed rad/s), the ideal mechanism's operating point)."""
    lub = joint.lubrication
    lub = replace(lub, roughness=run_in_roughness(joint.wear, lub.roughness, clearance - joint.clearance))
    if film is not None and lub.has_oil and lub.film_temperature is not None:
        from weftsim.joint.heat import with_film_temperature

        resolved, _ = with_film_temperature(replace(joint, clearance=clearance, lubrication=lub, bearing_wear=(),
                                                    journal_wear=()), *film)
        lub = resolved.lubrication
    return lub


def film_operating_point(scene: Scene, name: str) -> tuple[float, float] | None:
    """(mean load N, journal speed rad/s) of the ideal mechanism at joint ``name`` for the heat balance of a joint
    given an oil; None for a fixed viscosity or a dry joint."""
    joint = joint_of(scene, name)
    lub = joint.lubrication
    if lub is None or not lub.has_oil or lub.film_temperature is None:
        return None
    from weftsim.joint.bearing import mean_operating_point

    mean, _, omega = mean_operating_point(scene, name)
    return mean, omega


def worn_scene(scene: Scene, bearing: np.ndarray, journal: np.ndarray, revolutions: float,
               retry: bool = False, method: str | None = None, second: tuple | None = None) -> Scene:
    """``scene`` on the worn geometry (unworn when both profiles are zero) for ``revolutions``.

    ``bearing``, ``journal``: the profiles of the first wearing joint (:func:`wearing_joints`: E, or F
    when E is ideal); ``second``: (bearing, journal) of F when E and F both wear.  The solver tolerance
    of a worn geometry is at most WORN_RTOL, WORN_ATOL; ``retry``: RETRY_*.
    """
    joints = wearing_joints(scene)
    profiles = {joints[0]: (bearing, journal)}
    if second is not None:
        profiles["f"] = second
    worn = any(bool(np.any(b) or np.any(j)) for b, j in profiles.values())
    changes = {"joint" if name == "e" else "joint_f": _worn_joint(joint_of(scene, name), *pair,
                                                                  film_operating_point(scene, name))
               for name, pair in profiles.items()}
    scene = replace(scene, **changes)
    solver = scene.reference_solver
    if worn:
        solver = replace(solver, rtol=min(solver.rtol, WORN_RTOL), atol=min(solver.atol, WORN_ATOL))
    if retry:
        solver = replace(solver, rtol=min(solver.rtol, RETRY_RTOL), atol=min(solver.atol, RETRY_ATOL),
                         max_step=min(solver.max_step, RETRY_MAX_STEP))
    if method is not None:
        solver = replace(solver, method=method)
    return replace(scene, drive=replace(scene.drive, revolutions=revolutions), reference_solver=solver)


def _response(steps: dict, t0: float, joints: Sequence[str] = ("e",)) -> dict:
    """Statistics of the steady cycle: the mechanism's (rapier, torque) and each wearing joint's load
    (``joint_force_N``) and film (keys with the joint's letter, :data:`weftsim.wear.store.RESPONSE`)."""
    keep = steps["time_s"] >= t0
    t = steps["time_s"][keep]
    acc = channel_statistics(t, steps["rapier_acceleration_m_s2"][keep])
    torque = channel_statistics(t, steps["driving_torque_Nm"][keep])
    out = {"rapier_acceleration_rms_m_s2": acc["rms"], "rapier_acceleration_p99_m_s2": acc["p99_abs"],
           "driving_torque_rms_Nm": torque["rms"], "driving_torque_p99_Nm": torque["p99_abs"]}
    for joint in joints:
        tail = "" if joint == "e" else "_f"  # the channels' names (weftsim.post.results)
        # The joint's load (film + asperities + dry law, weftsim.joint.load): the contact_force_* keys keep their
        # names (stored wear states read them) and hold what the joint carries, oiled or dry.
        force = channel_statistics(t, joint_load(steps, f"joint_force{tail}_N")[keep])
        film = {"film_ratio_min": math.nan, "film_ratio_mean": math.nan, "mixed_fraction": math.nan}
        if f"film_ratio{tail}" in steps:  # a lubricated joint: the film ratio over the steady cycle
            ratio = steps[f"film_ratio{tail}"][keep]
            weights = time_weights(t)
            film = {"film_ratio_min": float(ratio.min()),
                    "film_ratio_mean": float(np.dot(weights, ratio) / weights.sum()),
                    "mixed_fraction": float(np.dot(weights, ratio < MIXED_FILM_RATIO) / weights.sum())}
        out.update({f"contact_force_{joint}_mean_N": force["mean"], f"contact_force_{joint}_p99_N": force["p99"],
                    f"contact_force_{joint}_max_N": force["max"],
                    **{f"{name}_{joint}": value for name, value in film.items()}})
    return out


def _sliding(wear: RunWear, per_rev: float, joint: str) -> dict:
    return {f"sliding_distance_per_rev_{joint}_m": wear.sliding_distance * per_rev,
            f"sliding_work_per_rev_{joint}_J": wear.sliding_work * per_rev,
            f"asperity_work_per_rev_{joint}_J": wear.asperity_work * per_rev,
            # Archard's load: the mean of F_N weighted by the sliding ds = |v_T| dt (not by dt)
            f"contact_force_sliding_mean_{joint}_N": wear.sliding_work / wear.sliding_distance
            if wear.sliding_distance > 0.0 else math.nan}


def _quiet(text: str) -> None:
    """An update's before-run warnings: the wear command reports the design checks of the scene once."""


def simulate_update(scene: Scene, bearing: np.ndarray, journal: np.ndarray,
                    second: tuple | None = None) -> tuple[RunWear, dict]:
    """Run the reference engine on the worn geometry; returns (wear per steady revolution, response).

    ``bearing``, ``journal``: the first wearing joint's profiles; ``second``: F's (bearing, journal) when E
    and F both wear, whose wear is then the returned RunWear's ``second``.  Raises WearError when the run fails.
    """
    from weftsim.engines import simulate
    from weftsim.model.dynamics import pack_parameters

    from weftsim.checks.guards import stop_requested

    joints = wearing_joints(scene)
    w = joint_of(scene, joints[0]).wear  # the run's revolutions: the first wearing joint's table
    attempts = ((False, None), (True, None), (True, IMPLICIT_METHOD))
    for retry, method in attempts:
        run_scene = worn_scene(scene, bearing, journal, w.settle_revolutions + w.revolutions_per_update, retry,
                               method, second)
        rows: dict[str, tuple] = {}
        result = simulate(run_scene, "reference", observe=lambda *a: rows.update(steps=a), on_warning=_quiet)
        if result.ok:
            break
        if stop_requested() is not None or result.solver_stats.get("failure") == "interrupted":
            raise WearInterrupted(result.message)
        if result.solver_stats.get("failure") == "memory":  # a tighter tolerance records more steps
            raise UpdateFailed(f"the simulation on the worn geometry failed: {result.message}")
    else:
        raise UpdateFailed(f"the simulation on the worn geometry failed (also at rtol {RETRY_RTOL:g} and with "
                           f"{IMPLICIT_METHOD}): {result.message}")
    t0 = w.settle_revolutions * scene.drive.period
    t, y, contact, impact = rows["steps"]
    keep = t >= t0
    prm = pack_parameters(run_scene)
    per_rev = 1.0 / w.revolutions_per_update
    wears = [run_wear(run_scene, prm, t[keep], y[keep], contact[keep], impact[keep], joint) for joint in joints]
    sliding = {key: value for joint, wear in zip(joints, wears) for key, value in _sliding(wear, per_rev, joint).items()}
    wear = replace(wears[0], joint=joints[0], second=replace(wears[1], joint=joints[1]) if len(wears) > 1 else None)
    return wear, {**_response(result.steps, t0, joints), "solver_rtol": run_scene.reference_solver.rtol, **sliding}


def wear_response(scene: Scene, wear: RunWear, steps: dict, rtol: float) -> dict:
    """The response of an update of joint E alone on any engine's run: statistics of the steady revolutions of
    the run's ``steps``, the solver's relative tolerance ``rtol`` and the sliding of ``wear`` per revolution
    (:func:`simulate_update`'s keys)."""
    w = scene.joint.wear
    t0 = w.settle_revolutions * scene.drive.period
    return {**_response(steps, t0, ("e",)), "solver_rtol": rtol, **_sliding(wear, 1.0 / w.revolutions_per_update, "e")}


def _part(scene: Scene, joint: str, wear: RunWear, bearing: np.ndarray, journal: np.ndarray, per_rev: float,
          revolutions: int) -> tuple[JointWear, float, float]:
    """(the joint's part of the update, the revolutions its update rule allows, the growth of c_eff over
    ``revolutions`` as a fraction)."""
    w = joint_of(scene, joint).wear
    rate_b, rate_j = wear.bearing * per_rev, wear.journal * per_rev
    growth = float(rate_b.max() + rate_j.max())
    c_eff = effective_clearance(joint_of(scene, joint).clearance, bearing, journal)
    allowed = math.inf if growth <= 0.0 else w.max_clearance_change * c_eff / growth
    part = JointWear(joint, bearing.copy(), journal.copy(), rate_b, rate_j,
                     (wear.bearing_volume + wear.journal_volume) * per_rev)
    return part, allowed, revolutions * growth / c_eff


def next_update(scene: Scene, hours_done: float, revolutions_done: float, bearing: np.ndarray, journal: np.ndarray,
                hours: float, second: tuple | None = None, simulate: Callable | None = None) -> Update:
    """Simulate the current geometry and choose the revolutions of this update (module docstring).

    ``bearing``, ``journal``: the first wearing joint's profiles; ``second``: F's when E and F both wear.
    ``simulate(scene, bearing, journal[, second]) -> (RunWear, response)``: the engine's update
    (:func:`weftsim.wear.engines.simulator`); None: :func:`simulate_update`, the reference engine.
    """
    joints = wearing_joints(scene)
    w = joint_of(scene, joints[0]).wear
    run = simulate_update if simulate is None else simulate
    if second is None:
        wear, response = run(scene, bearing, journal)
    else:
        wear, response = run(scene, bearing, journal, second)
    for joint, (b, j) in zip(joints, [(bearing, journal)] + ([second] if second is not None else [])):
        lub = joint_of(scene, joint).lubrication
        if lub is not None:  # the film's temperature and the run-in roughness the update ran with
            worn = _worn_joint(joint_of(scene, joint), b, j, film_operating_point(scene, joint)).lubrication
            response = {**response, f"film_temperature_{joint}_C": math.nan if worn.film_temperature is None
                        else worn.film_temperature, f"roughness_{joint}_um": 1e6 * worn.roughness}
    if scene.duty.stops_per_hour > 0.0:  # the stop-starts' wear on this geometry, per revolution of running
        from weftsim.wear.duty import with_stops

        engine = "reference" if simulate is None or simulate is simulate_update else "exudyn"
        worn = worn_scene(scene, bearing, journal, w.settle_revolutions + w.revolutions_per_update)
        try:
            wear, stops = with_stops(worn, wear, w.revolutions_per_update, engine)
        except WearError as exc:
            raise UpdateFailed(str(exc)) from None
        response = {**response, **stops}
    per_rev = 1.0 / w.revolutions_per_update
    profiles = [(bearing, journal)] + ([second] if second is not None else [])
    runs = [wear] + ([wear.second] if second is not None else [])
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    left = (hours - hours_done) * revs_per_hour
    parts, n = [], left
    for joint, run, (b, j) in zip(joints, runs, profiles):
        part, allowed, grown = _part(scene, joint, run, b, j, per_rev, w.revolutions_per_update)
        jw = joint_of(scene, joint).wear
        if allowed < w.revolutions_per_update and left > allowed:
            raise WearError(
                f"the wear is too fast to extrapolate: the {w.revolutions_per_update} revolutions of an update alone "
                f"grow the clearance at {joint.upper()} by {100 * grown:.3g} %, more than "
                f"joint_{joint}.wear.max_clearance_change = {100 * jw.max_clearance_change:g} % (wear coefficient "
                f"{jw.contact_wear_coefficient:g}, hardness {jw.bearing_hardness / 1e6:g} / {jw.journal_hardness / 1e6:g} MPa: "
                f"check [joint_{joint}.wear])")
        parts.append(part)
        n = min(n, allowed)
    first = parts[0]
    return Update(hours_done, revolutions_done, first.bearing, first.journal, n, first.rate_bearing,
                  first.rate_journal, first.volume_rate, response, first.joint, parts[1] if len(parts) > 1 else None)


def predict(scene: Scene, hours: float, updates: Sequence[Update] = (),
            on_update: Callable[[list[Update]], None] | None = None,
            stop: Callable[[], bool] | None = None, simulate: Callable | None = None) -> list[Update]:
    """Run the cycle extrapolation to ``hours`` of operation; returns the list of :class:`Update`.

    ``simulate``: the engine of each update's simulation (:func:`next_update`;
    :func:`weftsim.wear.engines.simulator` gives it by the engine's name; None: the reference engine);
    ``updates``: updates already done (resume: the run continues after the last);
    ``on_update(updates)``: called after each update (storing, progress); ``stop()``: True asks to
    end after the current update.  The last update simulates the final geometry, with N = 0; or,
    when the prediction ends at a geometric limit (:func:`ended_by_limit`), extrapolates up to it.
    A stop asked for while an update is simulated (:func:`weftsim.checks.guards.request_stop`) drops it.
    Every loose joint wears (:func:`wearing_joints`).
    """
    if not (0.0 < hours <= MAX_HOURS):
        raise WearError(f"--hours must be > 0 and at most {MAX_HOURS:g} h (114 years of continuous running), "
                        f"got {hours:g}")
    joints = wearing_joints(scene)
    if not joints:
        raise WearError("joint_e.clearance_mm is 0 (ideal joint): there is no contact to wear; give a clearance > 0")
    done = list(updates)
    if ended_by_limit(scene, done) is not None:  # resumed after the geometric limit: nothing to add
        return done
    if done:
        state = advance_update(done[-1], scene)
        if done[-1].step_revolutions == 0.0:  # the run had finished: nothing left but a longer request
            state = done[-1]
            done.pop()
    else:
        zeros = [np.zeros(joint_of(scene, joint).wear.profile_points) for joint in joints]
        parts = [JointWear(joint, z, z, z, z, 0.0) for joint, z in zip(joints, zeros)]
        state = _with_parts(Update(0.0, 0.0, zeros[0], zeros[0], 0.0, zeros[0], zeros[0], 0.0, {}), parts)
    backoffs = 0
    while True:
        finished = state.hours >= hours * (1.0 - 1e-12)
        second = None if state.second is None else (state.second.bearing, state.second.journal)
        try:
            update = next_update(scene, state.hours, state.revolutions, state.bearing, state.journal, hours, second,
                                 simulate)
        except WearInterrupted:
            return done  # the update in progress is dropped; the state holds the ones before it
        except UpdateFailed as exc:
            if not done or done[-1].step_revolutions <= 0.0 or backoffs >= MAX_BACKOFFS:
                if backoffs:
                    raise UpdateFailed(f"{exc} (after {backoffs} halvings of the update before it)") from None
                raise
            backoffs += 1  # a hard cycle: land on a slightly different geometry and go on
            done[-1] = replace(done[-1], step_revolutions=0.5 * done[-1].step_revolutions,
                               response={**done[-1].response, "backoffs_after": float(backoffs)})
            if on_update is not None:
                on_update(done)
            state = advance_update(done[-1], scene)
            continue
        backoffs = 0
        if finished:
            update = replace(update, step_revolutions=0.0)
        else:
            update = _cut_to_limit(update, scene)
        done.append(update)
        if on_update is not None:
            on_update(done)
        if finished or ended_by_limit(scene, done) is not None or (stop is not None and stop()):
            return done
        state = advance_update(update, scene)


def update_time(scene: Scene, engine: str = "reference") -> float:
    """Estimated wall-clock seconds of one wear update: the engine's estimate
    (the engine contract's ``estimate``, :mod:`weftsim.engines`) for its settle + steady revolutions at the
    solver tolerance of a worn geometry (:data:`WORN_RTOL` on the reference engine)."""
    from weftsim.engines import get

    w = joint_of(scene, (wearing_joints(scene) or ("e",))[0]).wear
    solver = replace(scene.reference_solver, rtol=min(scene.reference_solver.rtol, WORN_RTOL))
    one = replace(scene, drive=replace(scene.drive, revolutions=w.settle_revolutions + w.revolutions_per_update),
                  reference_solver=solver)
    return get(engine).estimate(one).run_time_s
