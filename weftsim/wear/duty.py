"""The loom's duty cycle in a wear prediction: the wear of one stop-start, added per hour of running.

A loom stops several times an hour (warp and weft breaks, ``[duty] stops_per_hour``) and starts again from
rest.  Each stop is simulated on the current worn geometry, on the engine of the prediction, as two transients
of the crank's prescribed motion (:func:`weftsim.physics.chain.crank_motion`, the one drive law both engines
read):

1. **run-down**: one revolution at full speed from the centred journal (not counted, as an update's settling
   revolution), then the crank slows to rest over ``rundown_revolutions`` (theta_dot = omega (1 - s(tau)),
   s the smooth step) and stands a quarter of a period while the last impacts die out; counted from the start
   of the ramp;
2. **start-up**: from rest with the journal lying on the bearing's wall below its centre (1e-3 c off it: the
   film squeezed out while the loom stood), the crank reaches full speed over ``startup_revolutions`` and turns one
   revolution more at full speed while the film builds up again; counted from the start.

Archard's law over both windows (the same rows and deposit as an update, :mod:`weftsim.wear.archard`) is the
wear of one stop-start; per revolution of running it weighs ``stops_per_hour / revolutions_per_hour``.  The
2-3 revolutions of a stop-start are not taken out of the running revolutions (0.01 % of an hour at 600 rpm).
``stops_per_hour = 0`` simulates nothing and leaves the steady prediction as it was, bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import WearError

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.wear.archard import RunWear

SETTLE_REVOLUTIONS = 1.0  # at full speed before the run-down: the journal's start from the centre is not counted
REST_PERIODS = 0.25  # standing still after the run-down, in periods of the full speed
AFTER_START_REVOLUTIONS = 1.0  # at full speed after the start-up ramp, while the film builds up


def check_duty(scene: Scene) -> None:
    """Refuse a duty cycle the transients cannot simulate, in one line."""
    duty = scene.duty
    if duty.stops_per_hour > 0.0 and not scene.joint_f.is_ideal:
        raise WearError("[duty] stops_per_hour > 0: the stop-start transient is simulated for joint E alone, and the "
                        "scene gives a clearance at F; set duty.stops_per_hour = 0 or make F ideal")


def transient_scenes(scene: Scene) -> tuple[tuple[Scene, float, float], tuple[Scene, float, float]]:
    """((run-down scene, t_from, t_to), (start-up scene, t_from, t_to)): the two transients of one stop-start on
    ``scene``'s geometry (worn or not) and the window (s) whose wear is counted (module docstring)."""
    duty, period = scene.duty, scene.drive.period
    down = 2.0 * duty.rundown_revolutions * period  # theta_dot falls as 1 - s: the crank turns omega T / 2
    up = 2.0 * duty.startup_revolutions * period
    t0 = SETTLE_REVOLUTIONS * period
    end_down = t0 + down + REST_PERIODS * period
    run_down = replace(scene, drive=replace(scene.drive, law="run_down", ramp_start=t0, ramp=down,
                                            revolutions=end_down / period))
    # The start-up from where the run-down stopped: the crank angle after it (mod one turn)
    stop_angle = math.fmod(scene.drive.speed * (t0 + 0.5 * down), 2.0 * math.pi)
    end_up = up + AFTER_START_REVOLUTIONS * period
    start_up = replace(scene, drive=replace(scene.drive, law="start_up", ramp_start=0.0, ramp=up,
                                            start_angle=stop_angle, revolutions=end_up / period))
    return (run_down, t0, end_down), (start_up, 0.0, end_up)


def _quiet(text: str) -> None:
    """A transient's before-run warnings: the wear command reports the scene's design checks once."""


def _window(run_scene: Scene, t_from: float, t_to: float, engine: str) -> RunWear:
    """Archard wear of ``run_scene``'s run on ``engine`` over [t_from, t_to] (joint E)."""
    from weftsim.model.dynamics import pack_parameters
    from weftsim.wear.archard import rows_from_contact, run_wear, wear_from_rows

    if engine == "reference":
        from weftsim.engines import simulate

        observed: dict[str, tuple] = {}
        result = simulate(run_scene, "reference", observe=lambda *a: observed.update(steps=a), on_warning=_quiet)
        if not result.ok:
            raise WearError(f"the stop-start transient ({run_scene.drive.law.replace('_', '-')}) failed on the "
                            f"reference engine: {result.message}")
        t, y, contact, impact = observed["steps"]
        keep = (t >= t_from) & (t <= t_to)
        return run_wear(run_scene, pack_parameters(run_scene), t[keep], y[keep], contact[keep], impact[keep])
    from weftsim.wear.worn_run import solve_worn

    result, (t, states, f_n, v_t), _ = solve_worn(run_scene, 0)
    if not result.ok:
        raise WearError(f"the stop-start transient ({run_scene.drive.law.replace('_', '-')}) failed on the "
                        f"Exudyn engine: {result.message}")
    keep = (t >= t_from) & (t <= t_to)
    rows = np.zeros((int(keep.sum()), 6))
    sliding = np.ascontiguousarray(np.where(f_n[keep] > 0.0, v_t[keep], np.nan))
    rows_from_contact(pack_parameters(run_scene), np.ascontiguousarray(t[keep]), np.ascontiguousarray(states[keep]),
                      np.ascontiguousarray(f_n[keep]), sliding, rows)  # fmt: skip
    return wear_from_rows(run_scene.joint, t[keep], rows)


def stop_start_wear(scene: Scene, engine: str = "reference") -> tuple[RunWear, RunWear]:
    """(run-down, start-up): the Archard wear of one stop-start of ``scene`` (its worn geometry as given) on
    ``engine`` (module docstring)."""
    check_duty(scene)
    (down, down_from, down_to), (up, up_from, up_to) = transient_scenes(scene)
    return _window(down, down_from, down_to, engine), _window(up, up_from, up_to, engine)


def add(*wears: RunWear, weights: tuple[float, ...]) -> RunWear:
    """The weighted sum of RunWears (profiles, volumes, works, distances)."""
    first = wears[0]
    total = {name: sum(w * getattr(r, name) for w, r in zip(weights, wears))
             for name in ("bearing", "journal", "bearing_volume", "journal_volume", "sliding_work", "sliding_distance",
                          "asperity_work")}
    return replace(first, **total)


def with_stops(scene: Scene, wear: RunWear, revolutions: int, engine: str) -> tuple[RunWear, dict]:
    """``wear`` (of ``revolutions`` steady revolutions) with the wear of the stop-starts those revolutions carry
    added, and the update's response keys of the duty cycle (``stop_start_share_e``: the stop-starts' share of
    the worn volume, ``stop_start_volume_e_mm3``: one stop-start's)."""
    duty = scene.duty
    if not duty.stops_per_hour > 0.0:
        return wear, {}
    from weftsim.wear.updates import SECONDS_PER_HOUR

    down, up = stop_start_wear(scene, engine)
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    stops = duty.stops_per_hour / revs_per_hour * revolutions  # stop-starts per ``revolutions`` of running
    combined = add(wear, down, up, weights=(1.0, stops, stops))
    one = down.bearing_volume + down.journal_volume + up.bearing_volume + up.journal_volume
    total = combined.bearing_volume + combined.journal_volume
    return combined, {"stop_start_volume_e_mm3": 1e9 * one,
                      "stop_start_start_up_share_e": (up.bearing_volume + up.journal_volume) / one if one > 0.0
                      else math.nan,
                      "stop_start_share_e": stops * one / total if total > 0.0 else math.nan}
