"""Files of a wear prediction: the resumable state, ``wear.csv``, the profiles, ``wear.json``.

Every name of a joint's quantity carries the joint's letter (docs/wear.md section 4): columns
``effective_clearance_e_mm``, ``contact_force_f_mean_N``; files ``wear_profile_e.csv``,
``wear_profile_journal_f.csv``; summary keys ``hours_to_limit_e``.  The mechanism's (hours, rapier,
torque) carry none.

The state (``wear_state.npz``) holds every :class:`~weftsim.wear.updates.Update` and the scene
it belongs to; it is rewritten (atomically) after each update, so an interrupted prediction
resumes at its last update (docs/wear.md section 4).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.post.output import write_atomic, write_csv
from weftsim.wear.extrapolate import Update, effective_clearance, joint_of, limit_hours, wearing_joints
# What a stored state is lives in weftsim.wear.state, read by weftsim.wear.resume too; re-exported here.
from weftsim.wear.state import JOINTS, JOINT_RESPONSE, LATER_RESPONSE, LEGACY_NAMES, LEGACY_RESPONSE, MECHANISM_RESPONSE, PARTS, RESPONSE, STATE, StateMismatch, scene_identity  # noqa: F401

if TYPE_CHECKING:
    from weftsim.input.params import Scene


def response_row(update: Update) -> list[float]:
    return [update.response.get(k, math.nan) for k in RESPONSE]


def save_state(outdir: Path, scene: Scene, updates: list[Update]) -> Path:
    arrays: dict[str, Any] = {  # keywords of np.savez (whose stub types one of them as allow_pickle)
        "scene": np.array(scene_identity(scene)),
        "hours": np.array([u.hours for u in updates]),
        "revolutions": np.array([u.revolutions for u in updates]),
        "step_revolutions": np.array([u.step_revolutions for u in updates]),
        "response": np.array([response_row(u) for u in updates]),
    }
    for joint in wearing_joints(scene):
        parts = [u.part(joint) for u in updates]
        for name in PARTS:
            arrays[f"{name}_{joint}"] = np.array([getattr(p, name) for p in parts])
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


def volumes(updates: list[Update], joint: str | None = None) -> np.ndarray:
    """Cumulative wear volume (bearing + journal, m^3) of ``joint`` (None: every joint) at the start of each update."""
    grown = np.array([(u.total_volume_rate if joint is None else u.part(joint).volume_rate) * u.step_revolutions
                      for u in updates])
    return np.concatenate([[0.0], np.cumsum(grown)[:-1]])


def table(scene: Scene, updates: list[Update]) -> dict[str, np.ndarray]:
    """Columns of ``wear.csv`` (one row per update, at the geometry it simulated)."""
    col: dict[str, Any] = {
        "hours": [u.hours for u in updates],
        "revolutions": [u.revolutions for u in updates],
        "update_revolutions": [u.step_revolutions for u in updates],
    }
    for joint in wearing_joints(scene):
        c0 = joint_of(scene, joint).clearance
        parts = [u.part(joint) for u in updates]
        col.update({
            f"effective_clearance_{joint}_mm": [1e3 * effective_clearance(c0, p.bearing, p.journal) for p in parts],
            f"bearing_wear_max_{joint}_mm": [1e3 * p.bearing.max() for p in parts],
            f"bearing_wear_mean_{joint}_mm": [1e3 * p.bearing.mean() for p in parts],
            f"journal_wear_max_{joint}_mm": [1e3 * p.journal.max() for p in parts],
            f"journal_wear_mean_{joint}_mm": [1e3 * p.journal.mean() for p in parts],
            f"wear_volume_{joint}_mm3": 1e9 * volumes(updates, joint),
        })
    for key in response_keys(scene):
        col[key] = [u.response.get(key, math.nan) for u in updates]
    return {k: np.asarray(v, dtype=float) for k, v in col.items()}


def response_keys(scene: Scene) -> tuple[str, ...]:
    """The :data:`RESPONSE` statistics of the mechanism and of the scene's wearing joints."""
    joints = wearing_joints(scene)
    return MECHANISM_RESPONSE + tuple(name.format(j=j) for j in joints for name in (*JOINT_RESPONSE, *LATER_RESPONSE))


def write_table(target: Path, scene: Scene, updates: list[Update]) -> Path:
    return write_csv(target, table(scene, updates))


def write_profiles(target: Path, updates: list[Update], which: str = "bearing", joint: str | None = None) -> Path:
    """``psi_deg`` and the worn depth (mm) of one body's profile of ``joint`` (default: the first wearing joint)
    at each update (column per update, ``h_b_e_mm_update3_12.5h``)."""
    parts = [u.part(joint) if joint is not None else u.worn()[0] for u in updates]
    letter = parts[0].joint
    n = parts[0].bearing.size
    columns = {"psi_deg": np.arange(n) * (360.0 / n)}
    for i, (u, p) in enumerate(zip(updates, parts)):
        columns[f"h_{which[0]}_{letter}_mm_update{i}_{u.hours:.6g}h"] = 1e3 * getattr(p, which)
    return write_csv(target, columns)


def summary(scene: Scene, updates: list[Update], hours: float, limit: float | None, wall_time: float) -> dict:
    """Contents of ``wear.json``: the mechanism's keys, then each wearing joint's with its letter.

    ``hours_to_limit`` is the first of the joints' ``hours_to_limit_<j>`` (the joint that needs service first,
    named by ``limit_joint``): a limit applies to every wearing joint.
    """
    from weftsim.input.scene import to_file_keys

    joints = wearing_joints(scene)
    last = updates[-1]
    out = {
        "scene": to_file_keys(scene),
        "engine": "reference",
        "joints": list(joints),
        "hours_requested": hours,
        "hours_reached": last.hours,
        "complete": last.step_revolutions == 0.0 and last.hours >= hours * (1.0 - 1e-12),
        "updates": len(updates),
        "revolutions": last.revolutions,
        "wear_volume_mm3": 1e9 * float(volumes(updates)[-1]),
        # hard cycles passed by halving the update before them (extrapolate.MAX_BACKOFFS)
        "backoffs": int(sum(np.nan_to_num(u.response.get("backoffs_after", 0.0)) > 0 for u in updates)),
        "wall_time_s": wall_time,
    }
    for joint in joints:
        c0 = joint_of(scene, joint).clearance
        part = last.part(joint)
        out.update({
            f"initial_clearance_{joint}_mm": 1e3 * c0,
            f"final_effective_clearance_{joint}_mm": 1e3 * effective_clearance(c0, part.bearing, part.journal),
            f"final_bearing_wear_max_{joint}_mm": 1e3 * float(part.bearing.max()),
            f"final_journal_wear_max_{joint}_mm": 1e3 * float(part.journal.max()),
            f"wear_volume_{joint}_mm3": 1e9 * float(volumes(updates, joint)[-1]),
        })
    out.update(archard_check(scene, updates))
    if limit is not None:
        out.update(limit_summary(scene, updates, limit))
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}


def limit_summary(scene: Scene, updates: list[Update], limit: float) -> dict:
    """``hours_to_limit_<j>`` of each wearing joint, and ``hours_to_limit`` / ``limit_joint`` of the first to reach
    ``limit`` (m); a ``note`` when none does."""
    out: dict = {"limit_clearance_mm": 1e3 * limit}
    reached = {joint: limit_hours(updates, joint_of(scene, joint).clearance, limit, joint)
               for joint in wearing_joints(scene)}
    out.update({f"hours_to_limit_{joint}": value for joint, value in reached.items()})
    first = min((v, j) for j, v in reached.items() if v is not None) if any(
        v is not None for v in reached.values()) else (None, None)
    out["hours_to_limit"], out["limit_joint"] = first
    if first[0] is None:
        out["note"] = (f"the effective clearance did not reach {1e3 * limit:g} mm at "
                       f"{' or '.join(j.upper() for j in reached)} within {updates[-1].hours:.6g} h")
    return out


def archard_check(scene: Scene, updates: list[Update]) -> dict:
    """The wear result checking itself (docs/wear.md section 4), for each wearing joint j: volumes three ways,
    and Archard's load.

    - ``wear_volume_<j>_mm3`` (the sum of each update's Archard volume per revolution times its N);
    - ``profile_volume_<j>_mm3``: the worn depth profiles integrated over their surfaces (h L R dpsi);
    - ``archard_volume_<j>_mm3``: k (1/H_b + 1/H_j) F_s S with the sliding distance S = sum N s_rev and the
      sliding-weighted mean load F_s = sum N W_rev / S (``sliding_weighted_mean_load_<j>_N``).
    ``time_mean_load_<j>_N`` is the plain time mean of the contact force (N-weighted over the updates):
    V = k F S / H with it is wrong wherever the load and the sliding speed vary together.
    """
    out = {}
    for joint in wearing_joints(scene):
        j = joint_of(scene, joint)
        w = j.wear
        last = updates[-1].part(joint)
        cell = 2.0 * math.pi / last.bearing.size
        profile = (float(last.bearing.sum()) * j.bearing_radius + float(last.journal.sum()) * j.journal_radius) \
            * j.bearing_length * cell
        n = np.array([u.step_revolutions for u in updates[:-1]])
        rows = [(u.response.get(f"sliding_distance_per_rev_{joint}_m", math.nan),
                 u.response.get(f"sliding_work_per_rev_{joint}_J", math.nan),
                 u.response.get(f"contact_force_{joint}_mean_N", math.nan),
                 u.response.get(f"asperity_work_per_rev_{joint}_J", math.nan)) for u in updates[:-1]]
        s_rev, w_rev, f_mean, a_rev = (np.array(c, dtype=float) for c in zip(*rows)) if rows else (np.zeros(0),) * 4
        distance = float(np.dot(n, s_rev))
        work = float(np.dot(n, w_rev))
        k_c, k_a = w.contact_wear_coefficient, w.asperity_wear_coefficient
        specific = k_c * (1.0 / w.bearing_hardness + 1.0 / w.journal_hardness)
        load = work / distance if distance > 0.0 else math.nan
        # Archard's volume: k_c on the solid contact's sliding work, k_a on the asperities' (the mixed regime)
        extra = 0.0 if k_a == k_c else (k_a / k_c - 1.0) * float(np.dot(n, a_rev))
        out.update({f"profile_volume_{joint}_mm3": 1e9 * profile,
                    f"archard_volume_{joint}_mm3": 1e9 * specific * (load * distance + extra) if distance > 0.0
                    else 0.0,
                    f"asperity_work_share_{joint}": float(np.dot(n, a_rev)) / work if work > 0.0 else math.nan,
                    f"sliding_distance_{joint}_m": distance,
                    f"sliding_weighted_mean_load_{joint}_N": load,
                    f"time_mean_load_{joint}_N": float(np.dot(n, f_mean) / n.sum()) if n.size and n.sum() > 0.0
                    else math.nan})
    return out
