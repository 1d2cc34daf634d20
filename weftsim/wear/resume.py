"""Resuming a wear prediction: the stored state read as untrusted input and checked before it is used.

``wear_state.npz`` (:func:`weftsim.wear.store.save_state`) may be damaged (a disk, a copy, a process
killed while another wrote it) or edited by hand.  A resumed prediction extrapolates from its last
update, so a wrong number there becomes a wrong answer that looks complete.  :func:`read_state`
therefore refuses, with one line naming what is wrong, a state that

- is not a readable archive of the arrays weftsim writes (:mod:`weftsim.post.npz_guard`: empty,
  truncated, garbage, a directory, a ZIP bomb, a header claiming more than the file holds);
- lacks an array, or has one of the wrong shape or kind (one row per update, one column per
  profile point of each wearing joint's ``[joint_*.wear] profile_points``; per-joint arrays are
  named with the joint's letter, ``bearing_e``, ``rate_journal_f``);
- belongs to another scene or other wear settings (its stored scene keys);
- holds a value that is not finite, a negative depth, rate or time, or a finished update before the last;
- disagrees with its own history: update 0 starts unworn at 0 h, and each later update's hours,
  revolutions and profiles are exactly the previous update advanced over its N revolutions
  (:func:`weftsim.wear.extrapolate.advance`; measured: equal to the last bit);
- does not match the SHA-256 checksum stored with its numbers, or has none: every state that names its
  joints was written with one (only a legacy state of joint E alone may predate it, and gets the other
  checks only);
- disagrees with the scene's wear model: each update's wear volume per revolution equals its two
  profiles' volumes (measured to 6e-16 relative), the journal's share of it is the bearing's
  hardness ratio (Archard: V_j / V_b = H_b / H_j), and no N exceeds what the update rule allows.

:func:`check_resume` refuses a request for fewer hours than the state already reaches.

A state written before the joints were named (joint E alone: ``bearing``, ``volume_rate``, a
response of :data:`weftsim.wear.store.LEGACY_RESPONSE`) is read as joint E's, with every check above
and its checksum over the names it was written with.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.errors import OutputError

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.wear.extrapolate import Update

WHAT = "a wear state"
SERIES = ("hours", "revolutions", "step_revolutions")
PROFILES = ("bearing", "journal", "rate_bearing", "rate_journal")
LEGACY = ("volume_rate", *PROFILES)  # the per-joint arrays of a state written before the joints were named
# Relative agreement required of numbers the state repeats: the stored history is recomputed with the
# same float operations (measured: equal to the last bit) and the volumes agree to 6e-16; 1e-9 is far
# above that round-off and far below any edit that changes a reported digit.
AGREE = 1e-9
MAX_SCENE_TEXT = 4 * 2**20  # characters of the stored scene keys (a few kB)


def digest(arrays: dict[str, Any]) -> str:
    """SHA-256 of the state's arrays (every one but ``digest``, by name, as float64 or text): the
    numbers no check can recompute (the response statistics) are covered by it."""
    import hashlib

    sha = hashlib.sha256()
    for name in sorted(arrays):
        if name == "digest":
            continue
        value = np.asarray(arrays[name])
        data = str(value[()]).encode() if value.dtype.kind == "U" else np.ascontiguousarray(value, "<f8").tobytes()
        sha.update(f"{name}:{value.shape}:".encode() + data)
    return sha.hexdigest()


def _advice(path: Path) -> str:
    return (f"; delete {path.name} to start the prediction over (the other files can stay), or choose another "
            "output directory with -o")


def _names(joints: tuple[str, ...], legacy: bool) -> dict[str, str]:
    """Name in this module (``bearing_e``) -> name in the file (``bearing`` in a legacy state)."""
    out = {name: name for name in SERIES}
    for joint in joints:
        for name in ("volume_rate", *PROFILES):
            out[f"{name}_{joint}"] = name if legacy else f"{name}_{joint}"
    return out


def read_state(path: Path, scene: Scene) -> list[Update]:
    """The checked updates stored at ``path`` (the module docstring says what is checked).

    Raises
    ------
    weftsim.wear.store.StateMismatch
        One line naming the problem, the file, and what to do.
    """
    from weftsim.post.npz_guard import DAMAGE, array_headers, open_archive, read_array
    from weftsim.wear.extrapolate import joint_of, wearing_joints
    from weftsim.wear.state import EARLIER_RESPONSE, LEGACY_RESPONSE, RESPONSE, StateMismatch, scene_identity

    joints = wearing_joints(scene)
    allowed = {"scene", "response", "digest", *SERIES, *LEGACY,
               *(f"{name}_{j}" for j in ("e", "f") for name in ("volume_rate", *PROFILES))}
    try:
        archive = open_archive(path, WHAT, "weftsim writes wear_state.npz as a file")
        with archive:
            headers = array_headers(path, archive, allowed, WHAT)
            shape, dtype = headers.get("scene", ((0,), np.dtype(float)))
            if shape != () or dtype.kind != "U" or dtype.itemsize > 4 * MAX_SCENE_TEXT:
                raise StateMismatch(f"{path}: damaged wear state: it holds no scene keys as one text{_advice(path)}")
            stored_scene = str(read_array(archive, "scene")[()])
            if stored_scene != scene_identity(scene):  # first: a state of another scene is not a damaged one
                raise StateMismatch(
                    f"{path} holds a wear prediction of another scene or other [joint_*.wear] settings; choose "
                    "another output directory with -o, or delete it to start over")
            legacy = "bearing" in headers or "volume_rate" in headers
            if legacy and joints != ("e",):
                raise StateMismatch(f"{path}: damaged wear state: it holds joint E's wear alone (written before F "
                                    f"could wear), and the scene wears {' and '.join(j.upper() for j in joints)}"
                                    f"{_advice(path)}")
            names = _names(joints, legacy)
            points = {j: joint_of(scene, j).wear.profile_points for j in joints}
            columns = len(LEGACY_RESPONSE) if legacy else len(RESPONSE)
            if not legacy and headers.get("response", ((0, 0),))[0][1:] == (len(EARLIER_RESPONSE),):
                columns = len(EARLIER_RESPONSE)  # written before the later columns (state.LATER_RESPONSE)
            problem = _shape_problem(headers, names, points, columns)
            if problem:
                raise StateMismatch(f"{path}: damaged wear state: {problem}{_advice(path)}")
            data = {name: np.asarray(read_array(archive, stored), dtype=float) for name, stored in names.items()}
            response = np.asarray(read_array(archive, "response"), dtype=float)
            stored = str(read_array(archive, "digest")[()]) if "digest" in headers else None
    except StateMismatch:
        raise
    except OutputError as exc:
        raise StateMismatch(f"{exc}{_advice(path)}") from None
    except DAMAGE as exc:
        raise StateMismatch(f"{path}: cannot be read as {WHAT}: damaged archive ({type(exc).__name__}: {exc})"
                            f"{_advice(path)}") from None
    written_response = response
    if legacy:
        response = _legacy_response(response)
    elif response.shape[1] < len(RESPONSE):
        response = np.hstack([response, np.full((response.shape[0], len(RESPONSE) - response.shape[1]), math.nan)])
    if stored is None and not legacy:  # every state naming its joints was written with its checksum
        raise StateMismatch(f"{path}: its checksum ('digest') is missing: weftsim has written one with every state "
                            "that names its joints (bearing_e, ...), so it was removed or the file damaged, and a "
                            f"resume would extrapolate from numbers nothing vouches for{_advice(path)}")
    problem = (_value_problem(data, response) or _history_problem(data, scene, joints)
               or _model_problem(data, scene, joints))
    if not problem and stored is not None:
        as_written = {names[name]: value for name, value in data.items()}
        if stored != digest({**as_written, "response": written_response, "scene": stored_scene}):
            problem = ("its numbers do not match the checksum stored with them (a state written before it had one "
                       "has none)")
    if problem:
        raise StateMismatch(f"{path}: {problem}: it was damaged or edited, and a resume would extrapolate from it"
                            f"{_advice(path)}")
    return _updates(data, response, joints)


def _legacy_response(response: np.ndarray) -> np.ndarray:
    """A legacy state's response columns (:data:`~weftsim.wear.store.LEGACY_RESPONSE`) in today's layout."""
    from weftsim.wear.state import LEGACY_NAMES, LEGACY_RESPONSE, RESPONSE

    out = np.full((response.shape[0], len(RESPONSE)), math.nan)
    for k, name in enumerate(LEGACY_RESPONSE):
        out[:, RESPONSE.index(LEGACY_NAMES[name])] = response[:, k]
    return out


def _shape_problem(headers: dict, names: dict[str, str], points: dict[str, int], responses: int) -> str:
    """What is wrong with the arrays' kinds and shapes ('' if nothing); ``names``: ours -> the file's."""
    missing = sorted({"scene", "response", *names.values()} - set(headers))
    if missing:
        return f"it lacks {', '.join(missing)}"
    extra = sorted(set(headers) - {"scene", "response", "digest", *names.values()})
    if extra:
        return f"it holds {', '.join(extra)}, arrays of a joint that does not wear in this scene"
    if "digest" in headers and (headers["digest"][0] != () or headers["digest"][1].kind != "U"
                                or headers["digest"][1].itemsize > 4 * 64):
        return "'digest' is not one SHA-256 text"
    for stored in (*names.values(), "response"):
        shape, dtype = headers[stored]
        if dtype.kind not in "iuf":
            return f"'{stored}' holds {dtype} values, not numbers"
    updates = headers["hours"][0]
    if len(updates) != 1 or updates[0] < 1:
        return f"'hours' has shape {headers['hours'][0]}; it holds one time per update (at least one)"
    n = updates[0]
    wanted: dict[str, tuple[int, ...]] = {"response": (n, responses)}
    for name, stored in names.items():
        joint = name.rpartition("_")[2]
        wanted[stored] = (n, points[joint]) if name.rpartition("_")[0] in PROFILES else (n,)
    for stored, shape in wanted.items():
        if headers[stored][0] != shape:
            profile = len(shape) == 2 and stored != "response"
            return (f"'{stored}' has shape {headers[stored][0]}, not {shape} ({n} updates"
                    + (", the profile points [joint_*.wear] profile_points says)" if profile else ")"))
    return ""


def _value_problem(data: dict, response: np.ndarray) -> str:
    for name, values in data.items():
        if not np.all(np.isfinite(values)):
            return f"'{name}' holds a value that is not finite"
        if np.any(values < 0.0):
            return f"'{name}' holds a negative value (times, revolutions, depths and rates are >= 0)"
    from weftsim.wear.state import RESPONSE

    # NaN is allowed: the film statistics of a dry joint (store.RESPONSE)
    if np.any(np.isinf(response)) or not np.all(response[:, RESPONSE.index("solver_rtol")] > 0.0):
        return "'response' holds an infinite statistic or a solver tolerance that is not > 0"
    if np.any(data["step_revolutions"][:-1] == 0.0):
        return "an update before the last extrapolates over 0 revolutions (only the final update does)"
    return ""


def _close(a, b) -> bool:
    return bool(np.all(np.abs(np.asarray(a) - np.asarray(b)) <= AGREE * np.maximum(np.abs(a), np.abs(b))))


def _history_problem(data: dict, scene: Scene, joints: tuple[str, ...]) -> str:
    """Update 0 unworn at 0 h; every later one its predecessor advanced over N revolutions."""
    from weftsim.wear.extrapolate import SECONDS_PER_HOUR

    if data["hours"][0] != 0.0 or data["revolutions"][0] != 0.0 or any(
            np.any(data[f"bearing_{j}"][0]) or np.any(data[f"journal_{j}"][0]) for j in joints):
        return "its first update does not start unworn at 0 h and 0 revolutions"
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    for i in range(1, data["hours"].size):
        n = data["step_revolutions"][i - 1]
        implied = {"hours": data["hours"][i - 1] + n / revs_per_hour, "revolutions": data["revolutions"][i - 1] + n}
        for j in joints:
            for body in ("bearing", "journal"):
                implied[f"{body}_{j}"] = data[f"{body}_{j}"][i - 1] + n * data[f"rate_{body}_{j}"][i - 1]
        for name, value in implied.items():
            if not _close(data[name][i], value):
                return (f"update {i}'s {name} is not what update {i - 1} implies (its {name} advanced over its "
                        f"{n:.6g} revolutions at the scene's speed)")
    return ""


def _model_problem(data: dict, scene: Scene, joints: tuple[str, ...]) -> str:
    """Each update's rates agree with each joint's geometry, hardness and update rule."""
    from weftsim.wear.extrapolate import effective_clearance, joint_of

    for j in joints:
        joint = joint_of(scene, j)
        wear = joint.wear
        cell = 2.0 * math.pi / wear.profile_points
        for i in range(data["hours"].size):
            rate_b, rate_j = data[f"rate_bearing_{j}"][i], data[f"rate_journal_{j}"][i]
            v_b = float(rate_b.sum()) * joint.bearing_length * joint.bearing_radius * cell
            v_j = float(rate_j.sum()) * joint.bearing_length * joint.journal_radius * cell
            if not _close(v_b + v_j, data[f"volume_rate_{j}"][i]):
                return f"update {i}'s volume_rate_{j} is not the volume of its wear-rate profiles"
            if v_b > 0.0 and not _close(v_j * wear.journal_hardness, v_b * wear.bearing_hardness):
                return (f"update {i}'s journal and bearing wear rates at {j.upper()} are not in the ratio of the "
                        f"scene's hardnesses (joint_{j}.wear.journal_hardness_mpa, bearing_hardness_mpa)")
            growth = float(rate_b.max() + rate_j.max())
            c_eff = effective_clearance(joint.clearance, data[f"bearing_{j}"][i], data[f"journal_{j}"][i])
            if growth > 0.0 and data["step_revolutions"][i] > wear.max_clearance_change * c_eff / growth * (1.0 + AGREE):
                return (f"update {i} extrapolates over more revolutions than joint_{j}.wear.max_clearance_change "
                        f"{wear.max_clearance_change:g} allows")
    return ""


def _updates(data: dict, response: np.ndarray, joints: tuple[str, ...]) -> list[Update]:
    from weftsim.wear.extrapolate import JointWear, Update
    from weftsim.wear.state import RESPONSE

    out = []
    for i in range(data["hours"].size):
        parts = [JointWear(j, data[f"bearing_{j}"][i].copy(), data[f"journal_{j}"][i].copy(),
                           data[f"rate_bearing_{j}"][i].copy(), data[f"rate_journal_{j}"][i].copy(),
                           float(data[f"volume_rate_{j}"][i])) for j in joints]
        first = parts[0]
        row = dict(zip(RESPONSE, map(float, response[i])))
        out.append(Update(float(data["hours"][i]), float(data["revolutions"][i]), first.bearing, first.journal,
                          float(data["step_revolutions"][i]), first.rate_bearing, first.rate_journal,
                          first.volume_rate, row, first.joint, parts[1] if len(parts) > 1 else None))
    return out


def check_resume(updates: list[Update], scene: Scene, hours: float, outdir: Path) -> None:
    """Refuse a resume asking for fewer hours than the stored state already reaches."""
    from weftsim.wear.extrapolate import SECONDS_PER_HOUR
    from weftsim.wear.state import STATE, StateMismatch

    if not updates:
        return
    last = updates[-1]
    reach = last.hours + last.step_revolutions / (scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR)
    if reach > hours * (1.0 + 1e-12):
        raise StateMismatch(
            f"{outdir / STATE} holds a wear prediction that reaches {reach:.6g} h, more than the --hours {hours:g} "
            f"asked for: ask for --hours {reach:.6g} or more to extend (or report) it, or choose another output "
            f"directory with -o (or delete {STATE} there) to predict {hours:g} h")
