"""Resuming a wear prediction: the stored state read as untrusted input and checked before it is used.

``wear_state.npz`` (:func:`weftsim.wear.store.save_state`) may be damaged (a disk, a copy, a process
killed while another wrote it) or edited by hand.  A resumed prediction extrapolates from its last
update, so a wrong number there becomes a wrong answer that looks complete.  :func:`read_state`
therefore refuses, with one line naming what is wrong, a state that

- is not a readable archive of the arrays weftsim writes (:mod:`weftsim.npz_guard`: empty,
  truncated, garbage, a directory, a ZIP bomb, a header claiming more than the file holds);
- lacks an array, or has one of the wrong shape or kind (one row per update, one column per
  profile point of the scene's ``[joint_e.wear] profile_points``);
- belongs to another scene or other wear settings (its stored scene keys);
- holds a value that is not finite, a negative depth, rate or time, or a finished update before the last;
- disagrees with its own history: update 0 starts unworn at 0 h, and each later update's hours,
  revolutions and profiles are exactly the previous update advanced over its N revolutions
  (:func:`weftsim.wear.extrapolate.advance`; measured: equal to the last bit);
- does not match the SHA-256 checksum stored with its numbers (states written before the checksum
  have none and get the other checks only);
- disagrees with the scene's wear model: each update's wear volume per revolution equals its two
  profiles' volumes (measured to 6e-16 relative), the journal's share of it is the bearing's
  hardness ratio (Archard: V_j / V_b = H_b / H_j), and no N exceeds what the update rule allows.

:func:`check_resume` refuses a request for fewer hours than the state already reaches.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import OutputError

if TYPE_CHECKING:
    from weftsim.params import Scene
    from weftsim.wear.extrapolate import Update

WHAT = "a wear state"
SERIES = ("hours", "revolutions", "step_revolutions", "volume_rate")
PROFILES = ("bearing", "journal", "rate_bearing", "rate_journal")
# Relative agreement required of numbers the state repeats: the stored history is recomputed with the
# same float operations (measured: equal to the last bit) and the volumes agree to 6e-16; 1e-9 is far
# above that round-off and far below any edit that changes a reported digit.
AGREE = 1e-9
MAX_SCENE_TEXT = 4 * 2**20  # characters of the stored scene keys (a few kB)


def digest(arrays: dict[str, np.ndarray]) -> str:
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


def read_state(path: Path, scene: Scene) -> list[Update]:
    """The checked updates stored at ``path`` (the module docstring says what is checked).

    Raises
    ------
    weftsim.wear.state.StateMismatch
        One line naming the problem, the file, and what to do.
    """
    from weftsim.npz_guard import DAMAGE, array_headers, open_archive, read_array
    from weftsim.wear.state import RESPONSE, StateMismatch, scene_identity

    expected = {"scene", *SERIES, *PROFILES, "response", "digest"}
    try:
        archive = open_archive(path, WHAT, "weftsim writes wear_state.npz as a file")
        with archive:
            headers = array_headers(path, archive, expected, WHAT)
            shape, dtype = headers.get("scene", ((0,), np.dtype(float)))
            if shape != () or dtype.kind != "U" or dtype.itemsize > 4 * MAX_SCENE_TEXT:
                raise StateMismatch(f"{path}: damaged wear state: it holds no scene keys as one text{_advice(path)}")
            stored_scene = str(read_array(archive, "scene")[()])
            if stored_scene != scene_identity(scene):  # first: a state of another scene is not a damaged one
                raise StateMismatch(
                    f"{path} holds a wear prediction of another scene or other [joint_e.wear] settings; choose "
                    "another output directory with -o, or delete it to start over")
            problem = _shape_problem(headers, scene.joint.wear.profile_points, len(RESPONSE))
            if problem:
                raise StateMismatch(f"{path}: damaged wear state: {problem}{_advice(path)}")
            data = {name: np.asarray(read_array(archive, name), dtype=float) for name in (*SERIES, *PROFILES)}
            response = np.asarray(read_array(archive, "response"), dtype=float)
            stored = str(read_array(archive, "digest")[()]) if "digest" in headers else None
    except StateMismatch:
        raise
    except OutputError as exc:
        raise StateMismatch(f"{exc}{_advice(path)}") from None
    except DAMAGE as exc:
        raise StateMismatch(f"{path}: cannot be read as {WHAT}: damaged archive ({type(exc).__name__}: {exc})"
                            f"{_advice(path)}") from None
    problem = _value_problem(data, response) or _history_problem(data, scene) or _model_problem(data, scene)
    if not problem and stored is not None and stored != digest({**data, "response": response, "scene": stored_scene}):
        problem = "its numbers do not match the checksum stored with them (a state written before it had one has none)"
    if problem:
        raise StateMismatch(f"{path}: {problem}: it was damaged or edited, and a resume would extrapolate from it"
                            f"{_advice(path)}")
    return _updates(data, response)


def _shape_problem(headers: dict, points: int, responses: int) -> str:
    """What is wrong with the arrays' kinds and shapes ('' if nothing)."""
    missing = sorted({"scene", *SERIES, *PROFILES, "response"} - set(headers))
    if missing:
        return f"it lacks {', '.join(missing)}"
    if "digest" in headers and (headers["digest"][0] != () or headers["digest"][1].kind != "U"
                                or headers["digest"][1].itemsize > 4 * 64):
        return "'digest' is not one SHA-256 text"
    for name in (*SERIES, *PROFILES, "response"):
        shape, dtype = headers[name]
        if dtype.kind not in "iuf":
            return f"'{name}' holds {dtype} values, not numbers"
    updates = headers["hours"][0]
    if len(updates) != 1 or updates[0] < 1:
        return f"'hours' has shape {headers['hours'][0]}; it holds one time per update (at least one)"
    n = updates[0]
    wanted = {**{name: (n,) for name in SERIES}, **{name: (n, points) for name in PROFILES},
              "response": (n, responses)}
    for name, shape in wanted.items():
        if headers[name][0] != shape:
            return (f"'{name}' has shape {headers[name][0]}, not {shape} ({n} updates"
                    + (f", {points} profile points as [joint_e.wear] profile_points says)" if name in PROFILES else ")"))
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


def _history_problem(data: dict, scene: Scene) -> str:
    """Update 0 unworn at 0 h; every later one its predecessor advanced over N revolutions."""
    from weftsim.wear.extrapolate import SECONDS_PER_HOUR

    if data["hours"][0] != 0.0 or data["revolutions"][0] != 0.0 or np.any(data["bearing"][0]) \
            or np.any(data["journal"][0]):
        return "its first update does not start unworn at 0 h and 0 revolutions"
    revs_per_hour = scene.drive.speed / (2.0 * math.pi) * SECONDS_PER_HOUR
    for i in range(1, data["hours"].size):
        n = data["step_revolutions"][i - 1]
        implied = {"hours": data["hours"][i - 1] + n / revs_per_hour, "revolutions": data["revolutions"][i - 1] + n,
                   "bearing": data["bearing"][i - 1] + n * data["rate_bearing"][i - 1],
                   "journal": data["journal"][i - 1] + n * data["rate_journal"][i - 1]}
        for name, value in implied.items():
            if not _close(data[name][i], value):
                return (f"update {i}'s {name} is not what update {i - 1} implies (its {name} advanced over its "
                        f"{n:.6g} revolutions at the scene's speed)")
    return ""


def _model_problem(data: dict, scene: Scene) -> str:
    """Each update's rates agree with the scene's geometry, hardness and update rule."""
    from weftsim.wear.extrapolate import effective_clearance

    joint, wear = scene.joint, scene.joint.wear
    cell = 2.0 * math.pi / wear.profile_points
    for i in range(data["hours"].size):
        rate_b, rate_j = data["rate_bearing"][i], data["rate_journal"][i]
        v_b = float(rate_b.sum()) * joint.bearing_length * joint.bearing_radius * cell
        v_j = float(rate_j.sum()) * joint.bearing_length * joint.journal_radius * cell
        if not _close(v_b + v_j, data["volume_rate"][i]):
            return f"update {i}'s volume_rate is not the volume of its wear-rate profiles"
        if v_b > 0.0 and not _close(v_j * wear.journal_hardness, v_b * wear.bearing_hardness):
            return (f"update {i}'s journal and bearing wear rates are not in the ratio of the scene's hardnesses "
                    "(joint_e.wear.journal_hardness_mpa, bearing_hardness_mpa)")
        growth = float(rate_b.max() + rate_j.max())
        c_eff = effective_clearance(joint.clearance, data["bearing"][i], data["journal"][i])
        if growth > 0.0 and data["step_revolutions"][i] > wear.max_clearance_change * c_eff / growth * (1.0 + AGREE):
            return (f"update {i} extrapolates over more revolutions than max_clearance_change "
                    f"{wear.max_clearance_change:g} allows")
    return ""


def _updates(data: dict, response: np.ndarray) -> list[Update]:
    from weftsim.wear.extrapolate import Update
    from weftsim.wear.state import RESPONSE

    return [Update(float(data["hours"][i]), float(data["revolutions"][i]), data["bearing"][i].copy(),
                   data["journal"][i].copy(), float(data["step_revolutions"][i]), data["rate_bearing"][i].copy(),
                   data["rate_journal"][i].copy(), float(data["volume_rate"][i]),
                   dict(zip(RESPONSE, map(float, response[i]))))
            for i in range(data["hours"].size)]


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
