"""Cycle extrapolation of the wear at joint E (docs/wear.md section 3).

One **update**: simulate the mechanism on the current worn geometry for ``settle_revolutions``
(not counted: the start from the centred journal) plus ``revolutions_per_update`` steady
revolutions, take the Archard wear per steady revolution (:mod:`.archard`), and extrapolate it
over N revolutions, as Flores (Mech. Mach. Theory 44, 2009) and Mukras et al. (Wear 268, 2010)
do.  N adapts: the effective clearance c_eff = c0 + max h_b + max h_j may grow by at most the
fraction ``max_clearance_change`` of its value per update,

    N = f c_eff / (max dh_b + max dh_j)        (dh per revolution; an upper bound of dc_eff/rev),

cut to the hours left.  Each update is one :class:`Update`: the state a run resumes from.
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


def worn_scene(scene: Scene, bearing: np.ndarray, journal: np.ndarray, revolutions: float,
               retry: bool = False) -> Scene:
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

    w = scene.joint.wear
    for retry in (False, True):
        run_scene = worn_scene(scene, bearing, journal, w.settle_revolutions + w.revolutions_per_update, retry)
        rows = {}
        result = reference.solve(run_scene, step_states=lambda *a: rows.update(steps=a))
        if result.ok:
            break
    else:
        raise WearError(f"the simulation on the worn geometry failed (also at rtol {RETRY_RTOL:g}): {result.message}")
    t0 = w.settle_revolutions * scene.drive.period
    t, y, contact, impact = rows["steps"]
    keep = t >= t0
    wear = run_wear(run_scene, pack_parameters(run_scene), t[keep], y[keep], contact[keep], impact[keep])
    return wear, {**_response(result.steps, t0), "solver_rtol": run_scene.reference_solver.rtol}


def next_update(scene: Scene, hours_done: float, revolutions_done: float, bearing: np.ndarray, journal: np.ndarray,
                hours: float) -> Update:
    """Simulate the current geometry and choose the revolutions of this update (module docstring)."""
    w = scene.joint.wear
    wear, response = simulate_update(scene, bearing, journal)
    per_rev = 1.0 / w.revolutions_per_update
    rate_b, rate_j = wear.bearing * per_rev, wear.journal * per_rev
    growth = float(rate_b.max() + rate_j.max())
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    left = (hours - hours_done) * revs_per_hour
    c_eff = effective_clearance(scene.joint.clearance, bearing, journal)
    n = left if growth <= 0.0 else min(left, w.max_clearance_change * c_eff / growth)
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
            stop: Callable[[], bool] | None = None) -> list[Update]:
    """Run the cycle extrapolation to ``hours`` of operation; returns the list of :class:`Update`.

    ``updates``: updates already done (resume: the run continues after the last);
    ``on_update(updates)``: called after each update (storing, progress); ``stop()``: True asks to
    end after the current update.  The last update simulates the final geometry, with N = 0.
    """
    if not hours > 0.0 or not math.isfinite(hours):
        raise WearError(f"--hours must be a finite number > 0, got {hours}")
    if scene.joint.is_ideal:
        raise WearError("joint_e.clearance_mm is 0 (ideal joint): there is no contact to wear; give a clearance > 0")
    n = scene.joint.wear.profile_points
    done = list(updates)
    if done:
        state = advance(done[-1], scene)
        if done[-1].step_revolutions == 0.0:  # the run had finished: nothing left but a longer request
            state = (done[-1].hours, done[-1].revolutions, done[-1].bearing, done[-1].journal)
            done.pop()
    else:
        state = (0.0, 0.0, np.zeros(n), np.zeros(n))
    while True:
        hours_done, revs_done, bearing, journal = state
        finished = hours_done >= hours * (1.0 - 1e-12)
        update = next_update(scene, hours_done, revs_done, bearing, journal, hours)
        if finished:
            update = replace(update, step_revolutions=0.0)
        done.append(update)
        if on_update is not None:
            on_update(done)
        if finished or (stop is not None and stop()):
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
