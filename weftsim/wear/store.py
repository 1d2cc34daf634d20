"""Files of a wear prediction: the resumable state, ``wear.csv``, ``wear_profile.csv``, ``wear.json``.

The state (``wear_state.npz``) holds every :class:`~weftsim.wear.extrapolate.Update` and the scene
it belongs to; it is rewritten (atomically) after each update, so an interrupted prediction
resumes at its last update (docs/wear.md section 4).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.output import write_atomic, write_csv
from weftsim.wear.extrapolate import Update, effective_clearance, limit_hours
# What a stored state is (the file's name, its response columns, its scene identity, the error of one that cannot
# be resumed) lives in weftsim.wear.state, read by weftsim.wear.resume too; re-exported here as before.
from weftsim.wear.state import RESPONSE, STATE, StateMismatch, scene_identity  # noqa: F401

if TYPE_CHECKING:
    from weftsim.params import Scene

def save_state(outdir: Path, scene: Scene, updates: list[Update]) -> Path:
    arrays = {
        "scene": np.array(scene_identity(scene)),
        "hours": np.array([u.hours for u in updates]),
        "revolutions": np.array([u.revolutions for u in updates]),
        "step_revolutions": np.array([u.step_revolutions for u in updates]),
        "volume_rate": np.array([u.volume_rate for u in updates]),
        "bearing": np.array([u.bearing for u in updates]),
        "journal": np.array([u.journal for u in updates]),
        "rate_bearing": np.array([u.rate_bearing for u in updates]),
        "rate_journal": np.array([u.rate_journal for u in updates]),
        "response": np.array([[u.response.get(k, math.nan) for k in RESPONSE] for u in updates]),
    }
    from weftsim.wear.resume import digest

    arrays["digest"] = np.array(digest(arrays))

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            np.savez(handle, **arrays)

    return write_atomic(Path(outdir) / STATE, write)


def load_state(outdir: Path, scene: Scene) -> list[Update]:
    """The updates stored in ``outdir`` (empty if none), checked by :func:`weftsim.wear.resume.read_state`.

    Raises StateMismatch if they are of another scene, damaged or inconsistent.
    """
    from weftsim.wear.resume import read_state

    path = Path(outdir) / STATE
    if not path.exists() and not path.is_symlink():
        return []
    return read_state(path, scene)


def volumes(updates: list[Update]) -> np.ndarray:
    """Cumulative wear volume (bearing + journal, m^3) at the start of each update."""
    grown = np.array([u.volume_rate * u.step_revolutions for u in updates])
    return np.concatenate([[0.0], np.cumsum(grown)[:-1]])


def table(scene: Scene, updates: list[Update]) -> dict[str, np.ndarray]:
    """Columns of ``wear.csv`` (one row per update, at the geometry it simulated)."""
    c0 = scene.joint.clearance
    col = {
        "hours": [u.hours for u in updates],
        "revolutions": [u.revolutions for u in updates],
        "update_revolutions": [u.step_revolutions for u in updates],
        "bearing_wear_max_mm": [1e3 * u.bearing.max() for u in updates],
        "bearing_wear_mean_mm": [1e3 * u.bearing.mean() for u in updates],
        "journal_wear_max_mm": [1e3 * u.journal.max() for u in updates],
        "journal_wear_mean_mm": [1e3 * u.journal.mean() for u in updates],
        "effective_clearance_mm": [1e3 * effective_clearance(c0, u.bearing, u.journal) for u in updates],
        "wear_volume_mm3": 1e9 * volumes(updates),
    }
    for key in RESPONSE:
        col[key] = [u.response.get(key, math.nan) for u in updates]
    return {k: np.asarray(v, dtype=float) for k, v in col.items()}


def write_table(target: Path, scene: Scene, updates: list[Update]) -> Path:
    return write_csv(target, table(scene, updates))


def write_profiles(target: Path, updates: list[Update], which: str = "bearing") -> Path:
    """``psi_deg`` and the worn depth (mm) of one body's profile at each update (column per update)."""
    n = updates[0].bearing.size
    columns = {"psi_deg": np.arange(n) * (360.0 / n)}
    for i, u in enumerate(updates):
        columns[f"h_{which[0]}_mm_update{i}_{u.hours:.6g}h"] = 1e3 * getattr(u, which)
    return write_csv(target, columns)


def summary(scene: Scene, updates: list[Update], hours: float, limit: float | None, wall_time: float) -> dict:
    """Contents of ``wear.json``."""
    from weftsim.scene import to_file_keys

    c0 = scene.joint.clearance
    last = updates[-1]
    out = {
        "scene": to_file_keys(scene),
        "engine": "reference",
        "hours_requested": hours,
        "hours_reached": last.hours,
        "complete": last.step_revolutions == 0.0 and last.hours >= hours * (1.0 - 1e-12),
        "updates": len(updates),
        "revolutions": last.revolutions,
        "initial_clearance_mm": 1e3 * c0,
        "final_effective_clearance_mm": 1e3 * effective_clearance(c0, last.bearing, last.journal),
        "final_bearing_wear_max_mm": 1e3 * float(last.bearing.max()),
        "final_journal_wear_max_mm": 1e3 * float(last.journal.max()),
        "wear_volume_mm3": 1e9 * float(volumes(updates)[-1]),
        **archard_check(scene, updates),
        # hard cycles passed by halving the update before them (extrapolate.MAX_BACKOFFS)
        "backoffs": int(sum(np.nan_to_num(u.response.get("backoffs_after", 0.0)) > 0 for u in updates)),
        "wall_time_s": wall_time,
    }
    if limit is not None:
        reached = limit_hours(updates, c0, limit)
        out["limit_clearance_mm"] = 1e3 * limit
        out["hours_to_limit"] = reached
        if reached is None:
            out["note"] = f"the effective clearance did not reach {1e3 * limit:g} mm within {last.hours:.6g} h"
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}


def archard_check(scene: Scene, updates: list[Update]) -> dict:
    """The wear result checking itself (docs/wear.md section 4): volumes three ways, and Archard's load.

    - ``wear_volume_mm3`` (the sum of each update's Archard volume per revolution times its N);
    - ``profile_volume_mm3``: the worn depth profiles integrated over their surfaces (h L R dpsi);
    - ``archard_volume_mm3``: k (1/H_b + 1/H_j) F_s S with the sliding distance S = sum N s_rev and the
      sliding-weighted mean load F_s = sum N W_rev / S (``sliding_weighted_mean_load_N``).
    ``time_mean_load_N`` is the plain time mean of the contact force (N-weighted over the updates):
    V = k F S / H with it is wrong wherever the load and the sliding speed vary together.
    """
    j = scene.joint
    w = j.wear
    last = updates[-1]
    cell = 2.0 * math.pi / last.bearing.size
    profile = (float(last.bearing.sum()) * j.bearing_radius + float(last.journal.sum()) * j.journal_radius) \
        * j.bearing_length * cell
    n = np.array([u.step_revolutions for u in updates[:-1]])
    rows = [(u.response.get("sliding_distance_per_rev_m", math.nan), u.response.get("sliding_work_per_rev_J", math.nan),
             u.response.get("contact_force_mean_N", math.nan)) for u in updates[:-1]]
    s_rev, w_rev, f_mean = (np.array(c, dtype=float) for c in zip(*rows)) if rows else (np.zeros(0),) * 3
    distance = float(np.dot(n, s_rev))
    work = float(np.dot(n, w_rev))
    specific = w.wear_coefficient * (1.0 / w.bearing_hardness + 1.0 / w.journal_hardness)
    load = work / distance if distance > 0.0 else math.nan
    return {"profile_volume_mm3": 1e9 * profile,
            "archard_volume_mm3": 1e9 * specific * load * distance if distance > 0.0 else 0.0,
            "sliding_distance_m": distance,
            "sliding_weighted_mean_load_N": load,
            "time_mean_load_N": float(np.dot(n, f_mean) / n.sum()) if n.size and n.sum() > 0.0 else math.nan}
