"""One simulated wear prediction of an ensemble: run to a clearance limit, resumably (docs/wear.md section 9).

:func:`run_job` is what the ensemble sends to the sweep machinery's pool (a local process pool or a
Dask cluster, :func:`weftsim.sweep.pool.executor`): plain data in (the scene, the limit, a
directory), plain data out (the effective clearance against hours).  It writes the job's
``wear_state.npz`` after every update, so an interrupted ensemble resumes each job at its last
update, and ``curve.json`` when done, so a finished job is not run again.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from weftsim.input.params import Scene

CURVE = "curve.json"
CURVE_VERSION = 3  # 2: two-ended hours, one update simulated at the limit; 3: a digest (older curves are run again)


def _digest(result: dict) -> str:
    """SHA-256 of the curve's result as written: a hand-edited curve.json no longer matches it."""
    import hashlib

    return hashlib.sha256(json.dumps(result, sort_keys=True, allow_nan=False).encode()).hexdigest()


def curve_problem(stored: object, identity: str, limit: float, horizon: float) -> str | None:
    """Why a job's ``curve.json`` cannot be reused (another request, an older version, edited or damaged:
    the job is then run again, resuming its wear state), or None."""
    if not isinstance(stored, dict) or not isinstance(stored.get("result"), dict):
        return "not a curve"
    if (stored.get("scene"), stored.get("limit"), stored.get("version"), stored.get("horizon")) != \
            (identity, limit, CURVE_VERSION, horizon):
        return "another scene, limit, horizon or version"
    result = stored["result"]
    try:
        if stored.get("digest") != _digest(result):
            return "edited or damaged (its digest does not match)"
    except (TypeError, ValueError):
        return "damaged"
    hours, clearance = result.get("hours"), result.get("clearance_m")
    if not (isinstance(hours, list) and isinstance(clearance, list) and len(hours) == len(clearance) >= 1):
        return "its hours and clearances differ in number"
    return None


def run_job(scene: Scene, limit: float, directory: str | Path, horizon: float | None = None) -> dict:
    """Predict the wear of ``scene`` until its effective clearance reaches ``limit`` (m).

    Returns a dict: ``hours`` and ``clearance_m`` (c_eff at each update, then at the limit),
    ``bearing_share`` (the bearing's part of max h_b + max h_j at the end), ``updates``,
    ``wall_s``; ``error`` (text) when the prediction failed.  A prediction that does not reach the
    limit within ``horizon`` hours (default :data:`~weftsim.wear.extrapolate.MAX_HOURS`) is
    **censored**, not failed: ``censored`` True, ``horizon_h``, and ``never`` (why it wears nothing,
    :func:`weftsim.wear.censored.no_wear_reason`) when its last update wears nothing at all.
    """
    from weftsim.errors import WearError
    from weftsim.wear import store
    from weftsim.wear.censored import no_wear_reason
    from weftsim.wear.extrapolate import MAX_HOURS, advance, effective_clearance, predict
    from weftsim.wear.life import prediction_stop_share

    horizon = MAX_HOURS if horizon is None else min(float(horizon), MAX_HOURS)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    identity = store.scene_identity(scene)
    done_file = directory / CURVE
    if done_file.is_file():
        try:
            stored = json.loads(done_file.read_text())
        except (OSError, ValueError, RecursionError):
            stored = None  # damaged: run it again (the state below resumes it)
        if curve_problem(stored, identity, limit, horizon) is None:
            return {**stored["result"], "reused": True}
    wall0, cpu0 = time.perf_counter(), time.process_time()
    c0 = scene.joint.clearance
    try:
        done = store.load_state(directory, scene)[:-1]  # the last update is simulated again (resume rule)
    except (store.StateMismatch, OSError, ValueError):
        done = []
    latest: list = list(done)

    def on_update(updates):
        latest[:] = updates
        store.save_state(directory, scene, updates)

    def start_clearance() -> float:
        return effective_clearance(c0, latest[-1].bearing, latest[-1].journal)

    # The prediction simulates one update at or beyond the limit, so that every update below it has the
    # wear rate at both of its ends (:func:`two_ended_hours`).
    result: dict = {"error": None, "censored": False, "never": None, "horizon_h": horizon}
    try:
        updates = predict(scene, horizon, done, on_update=on_update,
                          stop=lambda: bool(latest) and start_clearance() >= limit)
    except WearError as exc:
        updates = latest
        result["error"] = str(exc)
    if updates:
        hours = [u.hours for u in updates]
        clearance = [effective_clearance(c0, u.bearing, u.journal) for u in updates]
        end_hours, _, bearing, journal = advance(updates[-1], scene)
        end_c = effective_clearance(c0, bearing, journal)
        if end_hours > hours[-1]:
            hours.append(end_hours)
            clearance.append(end_c)
        depth_b, depth_j = float(bearing.max()), float(journal.max())
        # None: unreachable (the wear stops before it, two_ended_hours); JSON holds no Infinity
        result.update(hours=[v if math.isfinite(v) else None for v in two_ended_hours(hours, clearance)],
                      hours_one_ended=hours, clearance_m=clearance,
                      updates=len(updates),
                      bearing_share=depth_b / (depth_b + depth_j) if depth_b + depth_j > 0.0 else 0.5,
                      stop_start_share=prediction_stop_share(updates))
        if result["error"] is None and clearance[-1] < limit:  # censored: beyond the horizon, or never
            result["censored"] = True
            result["never"] = no_wear_reason(scene, updates[-1])
    elif result["error"] is None:
        result["error"] = "no update was completed"
    result["wall_s"] = time.perf_counter() - wall0
    result["cpu_s"] = time.process_time() - cpu0  # the worker's CPU (user + sys): the cost on a shared machine
    if result["error"] is None:
        done_file.write_text(json.dumps({"scene": identity, "limit": limit, "horizon": horizon,
                                          "version": CURVE_VERSION, "result": result, "digest": _digest(result)},
                                         allow_nan=False))
    return result


def two_ended_hours(hours: list[float], clearance: list[float]) -> list[float]:
    """The hours of a prediction's clearances from the wear rate at both ends of each update.

    The extrapolation (docs/wear.md section 3) grows the clearance over an update at the rate of the
    geometry it starts from (forward Euler in the geometry): accurate to O(f) with the update fraction f.
    With the rates r_i = dc_i / dh_i of two consecutive updates, the hours of update i are instead
    dc_i times the logarithmic mean of 1/r_i and 1/r_(i+1), exact when the rate changes exponentially with
    the clearance and O(f^2) otherwise (the geometries stay those simulated).  The last update keeps its
    one-ended hours; a rate of 0 at the far end of an update (the wear stops: a joint that runs in)
    makes its far end, and everything after it, unreachable (inf).
    """
    h = np.asarray(hours, dtype=float)
    c = np.asarray(clearance, dtype=float)
    dh, dc = np.diff(h), np.diff(c)
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(dc > 0.0, dh / dc, math.inf)  # 1 / r_i, h per m
    out = dh.copy()
    for i in range(dh.size - 1):
        if not dc[i] > 0.0:
            continue
        a, b = inverse[i], inverse[i + 1]
        if math.isinf(b):
            out[i] = math.inf
        elif a != b:
            out[i] = dc[i] * (b - a) / math.log(b / a)
    return [float(v) for v in np.concatenate([[h[0]], h[0] + np.cumsum(out)])]


def hours_at(result: dict, levels: np.ndarray) -> np.ndarray:
    """Hours at which the job's effective clearance reaches each of ``levels`` (m), linear between updates;
    inf where it does not reach a level (censored at the job's horizon)."""
    c = np.maximum.accumulate(np.asarray(result["clearance_m"], dtype=float))
    h = np.array([math.inf if v is None else v for v in result["hours"]], dtype=float)
    finite = np.isfinite(h)  # the curve ends where it becomes unreachable (two_ended_hours)
    last = int(np.argmin(finite)) if not np.all(finite) else h.size
    c, h = c[:last], h[:last]
    out = np.interp(levels, c, h, left=0.0, right=math.inf)
    if last < finite.size:
        out[levels > c[-1]] = math.inf
    return out
