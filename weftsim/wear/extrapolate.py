"""Cycle extrapolation of the wear at joint E (docs/wear.md section 3).

One **update**: simulate the mechanism on the current worn geometry for ``settle_revolutions``
(not counted: the start from the centred journal) plus ``revolutions_per_update`` steady
revolutions, take the Archard wear per steady revolution (:mod:`.archard`), and extrapolate it
over N revolutions, as Flores (Mech. Mach. Theory 44, 2009) and Mukras et al. (Wear 268, 2010)
do.  N adapts: the effective clearance c_eff = c0 + max h_b + max h_j may grow by at most the
fraction ``max_clearance_change`` of its value per update,

    N = f c_eff / (max dh_b + max dh_j)        (dh per revolution; an upper bound of dc_eff/rev),

cut to the hours left.  Each update is one :class:`Update`: the state a run resumes from.

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
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from weftsim.analysis import channel_statistics, time_weights
from weftsim.errors import WearError
from weftsim.wear.archard import run_wear

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from weftsim.params import Scene
    from weftsim.wear.archard import RunWear

SECONDS_PER_HOUR = 3600.0
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



@dataclass(frozen=True)
class Update:
    """One geometry update: the geometry simulated, the response on it, the wear it predicts.

    ``bearing``, ``journal``: worn depth profiles (m) *at the start* of the update (the geometry
    that was simulated); ``revolutions`` (crank revolutions before it, float) and ``hours``;
    ``step_revolutions``: N, the revolutions it extrapolates over; ``rate_bearing``,
    ``rate_journal``: worn depth per revolution (m); ``volume_rate``: bearing + journal wear
    volume per revolution (m^3); ``response``: statistics of the steady revolutions.
    """

    hours: float
    revolutions: float
    bearing: np.ndarray
    journal: np.ndarray
    step_revolutions: float
    rate_bearing: np.ndarray
    rate_journal: np.ndarray
    volume_rate: float
    response: dict


def effective_clearance(c0: float, bearing: np.ndarray, journal: np.ndarray) -> float:
    """c0 + max h_b + max h_j, m: the clearance where the two worn spots face each other (the load line)."""
    return c0 + float(np.max(bearing, initial=0.0)) + float(np.max(journal, initial=0.0))


def wall_slope(profile: np.ndarray, radius: float) -> float:
    """Largest slope |dh/dpsi| / R of a periodic worn-depth table (central differences), rad."""
    if profile.size < 3:
        return 0.0
    dpsi = 2.0 * math.pi / profile.size
    return float(np.max(np.abs(np.roll(profile, -1) - np.roll(profile, 1)))) / (2.0 * dpsi * radius)


def geometric_limit(scene: Scene, bearing: np.ndarray, journal: np.ndarray) -> str | None:
    """Why the worn geometry (bearing, journal; m) is beyond the model, as one clause, or None."""
    joint = scene.joint
    c_eff = effective_clearance(joint.clearance, bearing, journal)
    if c_eff >= joint.journal_radius * (1.0 - 1e-9):
        return (f"the effective clearance reaches the journal radius {joint.journal_radius * 1e3:g} mm (the bound "
                f"of joint_e.clearance_mm; the journal would be worn through)")
    slope = max(wall_slope(bearing, joint.bearing_radius), wall_slope(journal, joint.journal_radius))
    if slope >= MAX_WALL_SLOPE * (1.0 - 1e-9):
        return (f"a worn wall's slope reaches {MAX_WALL_SLOPE:g} rad (the small-wear geometry the contact "
                "model assumes, docs/wear.md section 2)")
    return None


def ended_by_limit(scene: Scene, updates: Sequence[Update]) -> str | None:
    """The :func:`geometric_limit` that ended the prediction ``updates`` at its last update, or None."""
    if not updates or updates[-1].step_revolutions == 0.0:
        return None
    return geometric_limit(scene, *advance(updates[-1], scene)[2:])


def _cut_to_limit(update: Update, scene: Scene) -> Update:
    """``update`` with its revolutions cut so the geometry just reaches :func:`geometric_limit` (unchanged if
    its whole extrapolation stays inside)."""
    if geometric_limit(scene, *advance(update, scene)[2:]) is None:
        return update
    inside, outside = 0.0, update.step_revolutions
    for _ in range(60):  # bisection to a relative 1e-18 of N: the limit is reached to round-off
        middle = 0.5 * (inside + outside)
        if geometric_limit(scene, *advance(replace(update, step_revolutions=middle), scene)[2:]) is None:
            inside = middle
        else:
            outside = middle
    return replace(update, step_revolutions=outside)


def worn_scene(scene: Scene, bearing: np.ndarray, journal: np.ndarray, revolutions: float,
               retry: bool = False, method: str | None = None) -> Scene:
    """``scene`` on the worn geometry (unworn when both profiles are zero) for ``revolutions``.

    The solver tolerance of a worn geometry is at most WORN_RTOL, WORN_ATOL; ``retry``: RETRY_*.
    """
    worn = bool(np.any(bearing) or np.any(journal))
    joint = replace(scene.joint, bearing_wear=tuple(map(float, bearing)) if worn else (),
                    journal_wear=tuple(map(float, journal)) if worn else ())
    solver = scene.reference_solver
    if worn:
        solver = replace(solver, rtol=min(solver.rtol, WORN_RTOL), atol=min(solver.atol, WORN_ATOL))
    if retry:
        solver = replace(solver, rtol=min(solver.rtol, RETRY_RTOL), atol=min(solver.atol, RETRY_ATOL),
                         max_step=min(solver.max_step, RETRY_MAX_STEP))
    if method is not None:
        solver = replace(solver, method=method)
    return replace(scene, joint=joint, drive=replace(scene.drive, revolutions=revolutions), reference_solver=solver)


def _response(steps: dict, t0: float) -> dict:
    keep = steps["time_s"] >= t0
    t = steps["time_s"][keep]
    acc = channel_statistics(t, steps["rapier_acceleration_m_s2"][keep])
    torque = channel_statistics(t, steps["driving_torque_Nm"][keep])
    force = channel_statistics(t, steps["contact_force_N"][keep])
    film = {"film_ratio_min": math.nan, "film_ratio_mean": math.nan, "mixed_fraction": math.nan}
    if "film_ratio" in steps:  # a lubricated joint E: the film ratio over the steady cycle
        ratio = steps["film_ratio"][keep]
        weights = time_weights(t)
        film = {"film_ratio_min": float(ratio.min()), "film_ratio_mean": float(np.dot(weights, ratio) / weights.sum()),
                "mixed_fraction": float(np.dot(weights, ratio < MIXED_FILM_RATIO) / weights.sum())}
    return {"rapier_acceleration_rms_m_s2": acc["rms"], "rapier_acceleration_p99_m_s2": acc["p99_abs"],
            "driving_torque_rms_Nm": torque["rms"], "driving_torque_p99_Nm": torque["p99_abs"],
            "contact_force_mean_N": force["mean"], "contact_force_p99_N": force["p99"],
            "contact_force_max_N": force["max"], **film}


def simulate_update(scene: Scene, bearing: np.ndarray, journal: np.ndarray) -> tuple[RunWear, dict]:
    """Run the reference engine on the worn geometry; returns (wear per steady revolution, response).

    Raises WearError when the run fails.
    """
    from weftsim import reference
    from weftsim.reference.dynamics import pack_parameters

    from weftsim.guards import stop_requested

    w = scene.joint.wear
    attempts = ((False, None), (True, None), (True, IMPLICIT_METHOD))
    for retry, method in attempts:
        run_scene = worn_scene(scene, bearing, journal, w.settle_revolutions + w.revolutions_per_update, retry,
                               method)
        rows = {}
        result = reference.solve(run_scene, step_states=lambda *a: rows.update(steps=a))
        if result.ok:
            break
        if stop_requested() is not None or result.solver_stats.get("failure") == "interrupted":
            raise WearInterrupted(result.message)
    else:
        raise UpdateFailed(f"the simulation on the worn geometry failed (also at rtol {RETRY_RTOL:g} and with "
                           f"{IMPLICIT_METHOD}): {result.message}")
    t0 = w.settle_revolutions * scene.drive.period
    t, y, contact, impact = rows["steps"]
    keep = t >= t0
    wear = run_wear(run_scene, pack_parameters(run_scene), t[keep], y[keep], contact[keep], impact[keep])
    return wear, wear_response(scene, wear, result.steps, run_scene.reference_solver.rtol)


def wear_response(scene: Scene, wear: RunWear, steps: dict, rtol: float) -> dict:
    """The response of an update: statistics of the steady revolutions of the run's ``steps``, the solver's
    relative tolerance ``rtol`` and the sliding of ``wear`` per revolution (any engine's run)."""
    w = scene.joint.wear
    per_rev = 1.0 / w.revolutions_per_update
    sliding = {"sliding_distance_per_rev_m": wear.sliding_distance * per_rev,
               "sliding_work_per_rev_J": wear.sliding_work * per_rev,
               # Archard's load: the mean of F_N weighted by the sliding ds = |v_T| dt (not by dt)
               "contact_force_sliding_mean_N": wear.sliding_work / wear.sliding_distance
               if wear.sliding_distance > 0.0 else math.nan}
    return {**_response(steps, w.settle_revolutions * scene.drive.period), "solver_rtol": rtol, **sliding}


def next_update(scene: Scene, hours_done: float, revolutions_done: float, bearing: np.ndarray, journal: np.ndarray,
                hours: float, simulate: Callable | None = None) -> Update:
    """Simulate the current geometry and choose the revolutions of this update (module docstring).

    ``simulate(scene, bearing, journal) -> (RunWear, response)``: the engine's update
    (:func:`weftsim.wear.engines.simulator`); None: :func:`simulate_update`, the reference engine.
    """
    w = scene.joint.wear
    wear, response = (simulate_update if simulate is None else simulate)(scene, bearing, journal)
    per_rev = 1.0 / w.revolutions_per_update
    rate_b, rate_j = wear.bearing * per_rev, wear.journal * per_rev
    growth = float(rate_b.max() + rate_j.max())
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    left = (hours - hours_done) * revs_per_hour
    c_eff = effective_clearance(scene.joint.clearance, bearing, journal)
    allowed = math.inf if growth <= 0.0 else w.max_clearance_change * c_eff / growth
    if allowed < w.revolutions_per_update and left > allowed:
        raise WearError(
            f"the wear is too fast to extrapolate: the {w.revolutions_per_update} revolutions of an update alone "
            f"grow the clearance by {100 * w.revolutions_per_update * growth / c_eff:.3g} %, more than "
            f"joint_e.wear.max_clearance_change = {100 * w.max_clearance_change:g} % (wear_coefficient "
            f"{w.wear_coefficient:g}, hardness {w.bearing_hardness / 1e6:g} / {w.journal_hardness / 1e6:g} MPa: "
            "check [joint_e.wear])")
    n = min(left, allowed)
    return Update(hours_done, revolutions_done, bearing.copy(), journal.copy(), n, rate_b, rate_j,
                  (wear.bearing_volume + wear.journal_volume) * per_rev, response)


def advance(update: Update, scene: Scene) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(hours, revolutions, bearing, journal) after the update's N revolutions."""
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    n = update.step_revolutions
    return (update.hours + n / revs_per_hour, update.revolutions + n,
            update.bearing + n * update.rate_bearing, update.journal + n * update.rate_journal)


def predict(scene: Scene, hours: float, updates: Sequence[Update] = (),
            on_update: Callable[[list[Update]], None] | None = None,
            stop: Callable[[], bool] | None = None, simulate: Callable | None = None) -> list[Update]:
    """Run the cycle extrapolation to ``hours`` of operation; returns the list of :class:`Update`.

    ``simulate``: the engine of each update's simulation (:func:`next_update`; :func:`weftsim.wear.engines.simulator`
    gives it by the engine's name; None: the reference engine);
    ``updates``: updates already done (resume: the run continues after the last);
    ``on_update(updates)``: called after each update (storing, progress); ``stop()``: True asks to
    end after the current update.  The last update simulates the final geometry, with N = 0; or,
    when the prediction ends at a geometric limit (:func:`ended_by_limit`), extrapolates up to it.
    A stop asked for while an update is simulated (:func:`weftsim.guards.request_stop`) drops it.
    """
    if not (0.0 < hours <= MAX_HOURS):
        raise WearError(f"--hours must be > 0 and at most {MAX_HOURS:g} h (114 years of continuous running), "
                        f"got {hours:g}")
    if scene.joint.is_ideal:
        raise WearError("joint_e.clearance_mm is 0 (ideal joint): there is no contact to wear; give a clearance > 0")
    n = scene.joint.wear.profile_points
    done = list(updates)
    if ended_by_limit(scene, done) is not None:  # resumed after the geometric limit: nothing to add
        return done
    if done:
        state = advance(done[-1], scene)
        if done[-1].step_revolutions == 0.0:  # the run had finished: nothing left but a longer request
            state = (done[-1].hours, done[-1].revolutions, done[-1].bearing, done[-1].journal)
            done.pop()
    else:
        state = (0.0, 0.0, np.zeros(n), np.zeros(n))
    backoffs = 0
    while True:
        hours_done, revs_done, bearing, journal = state
        finished = hours_done >= hours * (1.0 - 1e-12)
        try:
            update = next_update(scene, hours_done, revs_done, bearing, journal, hours, simulate)
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
            state = advance(done[-1], scene)
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
        state = advance(update, scene)


def limit_hours(updates: Sequence[Update], c0: float, limit: float) -> float | None:
    """Operating hours at which c_eff first reaches ``limit`` (m), linear between updates; None if never."""
    c = [effective_clearance(c0, u.bearing, u.journal) for u in updates]
    h = [u.hours for u in updates]
    for i in range(1, len(c)):
        if c[i] >= limit > c[i - 1]:
            return h[i - 1] + (h[i] - h[i - 1]) * (limit - c[i - 1]) / (c[i] - c[i - 1])
    if c and c[0] >= limit:
        return 0.0
    return None


def update_time(scene: Scene, engine: str = "reference") -> float:
    """Estimated wall-clock seconds of one wear update: the engine's estimate
    (:func:`weftsim.progress.estimate_run_time`) for its settle + steady revolutions at the solver
    tolerance of a worn geometry (:data:`WORN_RTOL` on the reference engine)."""
    from weftsim.progress import estimate_run_time

    w = scene.joint.wear
    solver = replace(scene.reference_solver, rtol=min(scene.reference_solver.rtol, WORN_RTOL))
    one = replace(scene, drive=replace(scene.drive, revolutions=w.settle_revolutions + w.revolutions_per_update),
                  reference_solver=solver)
    return estimate_run_time(one, engine)
