"""One simulated wear prediction of an ensemble: run to a clearance limit, resumably (docs/wear.md section 7).

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


def run_job(scene: Scene, limit: float, directory: str) -> dict:
    """Predict the wear of ``scene`` until its effective clearance reaches ``limit`` (m).

    Returns a dict: ``hours`` and ``clearance_m`` (c_eff at each update, then at the limit),
    ``bearing_share`` (the bearing's part of max h_b + max h_j at the end), ``updates``,
    ``wall_s``; ``error`` (text) when the prediction failed or never reaches the limit.
    """
    from weftsim.errors import WearError
    from weftsim.wear import store
    from weftsim.wear.extrapolate import MAX_HOURS, advance, effective_clearance, predict

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    identity = store.scene_identity(scene)
    done_file = directory / CURVE
    if done_file.exists():
        try:
            stored = json.loads(done_file.read_text())
            if stored.get("scene") == identity and stored.get("limit") == limit:
                return {**stored["result"], "reused": True}
        except (OSError, ValueError, KeyError, TypeError):
            pass  # damaged: run it again (the state below resumes it)
    wall0 = time.perf_counter()
    c0 = scene.joint.clearance
    try:
        done = store.load_state(directory, scene)[:-1]  # the last update is simulated again (resume rule)
    except (store.StateMismatch, OSError, ValueError):
        done = []
    latest: list = list(done)

    def next_clearance() -> float:
        _, _, bearing, journal = advance(latest[-1], scene)
        return effective_clearance(c0, bearing, journal)

    def on_update(updates):
        latest[:] = updates
        store.save_state(directory, scene, updates)

    result: dict = {"error": None}
    try:
        updates = predict(scene, MAX_HOURS, done, on_update=on_update,
                          stop=lambda: bool(latest) and next_clearance() >= limit)
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
        result.update(hours=hours, clearance_m=clearance, updates=len(updates),
                      bearing_share=depth_b / (depth_b + depth_j) if depth_b + depth_j > 0.0 else 0.5)
        if result["error"] is None and clearance[-1] < limit:
            result["error"] = (f"the effective clearance stays below the limit ({1e3 * clearance[-1]:.4g} mm after "
                               f"{hours[-1]:.4g} h): the joint does not wear there (full film?)")
    elif result["error"] is None:
        result["error"] = "no update was completed"
    result["wall_s"] = time.perf_counter() - wall0
    if result["error"] is None:
        done_file.write_text(json.dumps({"scene": identity, "limit": limit, "result": result}))
    return result


def hours_at(result: dict, levels: np.ndarray) -> np.ndarray:
    """Hours at which the job's effective clearance reaches each of ``levels`` (m), linear between updates."""
    c = np.maximum.accumulate(np.asarray(result["clearance_m"], dtype=float))
    h = np.asarray(result["hours"], dtype=float)
    out = np.interp(levels, c, h, left=0.0, right=math.inf)
    return out
