"""Reading a saved result (``result.npz``) as untrusted input: sizes from the headers first.

A result file may have been damaged by a disk or a copy, or edited by a person, so
:func:`read_npz` checks it in this order and refuses it with one line
(:class:`weftsim.errors.OutputError`) at the first problem:

Steps 1-3 are :mod:`weftsim.post.npz_guard` (shared with the wear state):

1. the path: present, a regular file, not empty, a ZIP archive (a lone ``.npy`` is named as such);
2. the archive's directory: the members weftsim writes and no others, none twice, none encrypted,
   and the uncompressed size each member declares (the ZIP directory; a member is never read past
   it) within the memory available and not a ZIP bomb;
3. every array's own header (NumPy format: dtype and shape, a few hundred bytes): a real numeric
   1-D channel, every channel of a table as long as its ``time_s``, the text of ``meta`` a string
   no longer than :data:`MAX_META_BYTES`, and the bytes the header implies equal to the bytes the
   member declares.  Only then is any array read, so a header claiming 10^12 elements or a small
   file that inflates to gigabytes is refused before anything is allocated;
4. ``meta``: JSON with every key :func:`weftsim.post.results.save_npz` writes, each of its type; the scene
   rebuilt field by field (each of its type, none unknown, none of the fields the format has always
   written missing) and validated as a scene file is (:func:`weftsim.input.scene.scene_from_keys`);
5. the data against the scene: joint F's channels present exactly when the scene gives F a
   clearance, ``time_s`` finite and not decreasing, a successful run's steps reaching the scene's
   end time.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import types
import typing
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from weftsim.input import params
from weftsim.errors import OutputError
from weftsim.post.npz_guard import DAMAGE, array_headers, fail, open_archive, read_array, size_text

# The JSON text of meta: scene, statistics, events (a few kB; a worn scene's profiles ~20 kB).
MAX_META_BYTES = 16 * 2**20
TABLES = ("samples", "steps")
META_TYPES = {"format": str, "scene": dict, "engine": str, "status": str, "message": str, "solver_stats": dict,
              "events": dict, "plausibility": dict, "path": dict}
# The fields of the scene that every file of format weftsim-result/1 holds (the scene of the first
# release of the format); a field added later may be absent from an older file and keeps its default.
FORMAT_1_FIELDS: dict[str, tuple[str, ...]] = {
    "Scene": ("name", "geometry", "inertia", "joint", "drive", "reference_solver", "exudyn_solver", "output",
              "compare", "limits", "source"),
    "Geometry": ("crank_inclination", "rocker_arm_angle", "l_oe", "l_ef", "l_fg", "l_og", "fourbar_branch",
                 "sector_pitch_radius", "pinion_pitch_radius", "rapier_gear_pitch_radius"),
    "Inertia": ("crank_inertia", "coupler_mass", "coupler_inertia", "rocker_mass", "rocker_com", "rocker_inertia",
                "rod_mass", "rod_inertia", "sector_inertia", "pinion_gear_inertia", "rapier_mass", "gravity"),
    "Material": ("youngs_modulus", "poisson_ratio", "yield_strength"),
    "ClearanceJoint": ("clearance", "journal_radius", "bearing_length", "journal_material", "bearing_material", "law",
                       "restitution", "friction_coefficient", "friction_velocities", "min_impact_velocity",
                       "impact_velocity_rule"),
    "Drive": ("speed", "revolutions"),
    "ReferenceSolver": ("method", "rtol", "atol", "max_step"),
    "Output": ("sample_angle",),
    "ExudynSolver": ("model", "step_control", "local_error", "step_size", "spectral_radius", "modified_newton",
                     "newton_relative_tolerance", "newton_max_iterations", "callback", "explicit_method",
                     "relative_tolerance", "absolute_tolerance"),
    "CompareTolerance": ("first_contact_angle", "first_revolution_peaks", "rms", "percentile_99", "ideal_curves"),
    "Limits": ("max_wall_time", "max_steps", "max_penetration", "min_step", "max_energy_error", "max_damping_ratio"),
}


WHAT = "a weftsim result"


def _fail(path: Path, text: str) -> OutputError:
    return fail(path, WHAT, text)


def check_channel_headers(path: Path, headers: dict[str, tuple[tuple, np.dtype]], names: tuple[str, ...]) -> None:
    """Each channel of each table: present, real numbers, 1-D and as long as the table's ``time_s``."""
    for table in TABLES:
        missing = [n for n in names if f"{table}/{n}" not in headers]
        if missing:
            raise _fail(path, f"not a complete weftsim result: table {table!r} lacks channel(s) "
                              f"{', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}")
        for name in names:
            shape, dtype = headers[f"{table}/{name}"]
            if dtype.kind not in "biuf":
                raise _fail(path, f"channel {table}/{name} holds {dtype} values; a channel holds real numbers")
            if len(shape) != 1:
                raise _fail(path, f"channel {table}/{name} has shape {shape}; a channel is 1-D (one value a row)")
        rows = headers[f"{table}/time_s"][0][0]
        uneven = {n: headers[f"{table}/{n}"][0][0] for n in names if headers[f"{table}/{n}"][0][0] != rows}
        if uneven:
            first = next(iter(uneven))
            raise _fail(path, f"channels of table {table!r} differ in length: time_s has {rows} rows, {first} "
                              f"{uneven[first]}{f' (and {len(uneven) - 1} more)' if len(uneven) > 1 else ''}")


def read_meta(path: Path, archive: zipfile.ZipFile, headers: dict[str, tuple[tuple, np.dtype]]) -> dict:
    """``meta`` as a dict with every key :data:`META_TYPES` names, each of its type."""
    from weftsim.post.results import ENGINES, NPZ_FORMAT, STATUSES

    if "meta" not in headers:
        raise _fail(path, "not a complete weftsim result: it has no 'meta' (the run's scene and status)")
    meta_shape, meta_dtype = headers["meta"]
    if meta_shape != () or meta_dtype.kind != "U":
        raise _fail(path, f"'meta' is {meta_dtype} of shape {meta_shape}, not the one JSON text weftsim writes")
    if meta_dtype.itemsize > MAX_META_BYTES * 4:  # 4 bytes a character
        raise _fail(path, f"'meta' is {size_text(meta_dtype.itemsize)} long; weftsim's is a few kB (at most "
                          f"{size_text(MAX_META_BYTES)})")
    text = str(read_array(archive, "meta")[()])
    try:
        meta = json.loads(text)
    except RecursionError:
        raise _fail(path, "'meta' nests too deeply to be weftsim's") from None
    except ValueError as exc:
        raise _fail(path, f"'meta' is not JSON ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != NPZ_FORMAT:
        found = meta.get("format") if isinstance(meta, dict) else type(meta).__name__
        raise OutputError(f"{path}: not a weftsim result of format {NPZ_FORMAT} (found {str(found)[:80]!r})")
    missing = [k for k in META_TYPES if k not in meta]
    if missing:
        raise _fail(path, f"'meta' lacks {', '.join(missing)} (every weftsim result of {NPZ_FORMAT} gives "
                          f"{', '.join(META_TYPES)})")
    for key, kind in META_TYPES.items():
        if not isinstance(meta[key], kind):
            raise _fail(path, f"'meta' key {key!r} must be a {'JSON object' if kind is dict else 'string'}, "
                              f"got {_short(meta[key])}")
    # Other keys are ignored: nothing reads them (a later version may add some under the same format).
    if meta["engine"] not in ENGINES:
        raise _fail(path, f"'meta' engine must be one of {', '.join(ENGINES)}, got {_short(meta['engine'])}")
    if meta["status"] not in STATUSES:
        raise _fail(path, f"'meta' status must be one of {', '.join(STATUSES)}, got {_short(meta['status'])}")
    first = meta["events"].get("first_contact_time_s")
    if first is not None and not (_number(first) and math.isfinite(first) and first >= 0.0):
        raise _fail(path, f"'meta' events.first_contact_time_s must be a time >= 0 (s) or null, got {_short(first)}")
    wall = meta["solver_stats"].get("wall_time_s")
    if wall is not None and not _number(wall):
        raise _fail(path, f"'meta' solver_stats.wall_time_s must be a number, got {_short(wall)}")
    if not all(isinstance(v, str) for v in meta["path"].values()):
        raise _fail(path, "'meta' path must map model, method and reason to text")
    return meta


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _field_type(hint: Any) -> tuple[type | None, bool, Any]:
    """(dataclass or None, optional, plain hint) of a field's type hint."""
    optional = False
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        optional = type(None) in args
        rest = [a for a in args if a is not type(None)]
        hint = rest[0] if len(rest) == 1 else hint
    return (hint if isinstance(hint, type) and dataclasses.is_dataclass(hint) else None), optional, hint


def _value(hint: Any, value: Any, where: str) -> Any:
    """``value`` checked against a plain field hint (float, int, str, bool, tuple of floats or of names)."""
    if hint is float and _number(value):
        return float(value) if isinstance(value, int) else value
    if hint is int and isinstance(value, int) and not isinstance(value, bool):
        return value
    if hint in (str, bool) and isinstance(value, hint):
        return value
    if typing.get_origin(hint) is tuple and typing.get_args(hint) == (str, Ellipsis):  # names (joint_f_inherits)
        if isinstance(value, list) and all(isinstance(v, str) for v in value):
            return tuple(value)
        raise ValueError(f"scene field {where} must be a list of names, got {_short(value)}")
    if typing.get_origin(hint) is tuple or hint is tuple:
        if isinstance(value, list) and all(_number(v) for v in value):
            args = typing.get_args(hint)
            if args and args[-1] is not Ellipsis and len(args) != len(value):
                raise ValueError(f"scene field {where} must be a list of {len(args)} numbers, got {_short(value)}")
            return tuple(float(v) for v in value)
        raise ValueError(f"scene field {where} must be a list of numbers, got {_short(value)}")
    if hint in (float, int, str, bool):
        kind = {float: "a number", int: "a whole number", str: "text", bool: "true or false"}[hint]
        raise ValueError(f"scene field {where} must be {kind}, got {_short(value)}")
    if typing.get_origin(hint) is typing.Literal:
        if value in typing.get_args(hint):
            return value
        raise ValueError(f"scene field {where} must be one of {typing.get_args(hint)}, got {_short(value)}")
    # Another kind of field (none today): its value is checked with the whole scene (check_scene).
    if isinstance(value, (str, int, float, bool, list)):
        return tuple(value) if isinstance(value, list) else value
    raise ValueError(f"scene field {where} must be a number, text or a list, got {_short(value)}")


def rebuild(cls: type, data: Any, where: str = "scene") -> Any:
    """The dataclass ``cls`` from its saved dict, every field checked (ValueError naming the field)."""
    if not isinstance(data, dict):
        raise ValueError(f"{where} must be a JSON object of {cls.__name__}'s fields, got {_short(data)}")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ValueError(f"{where} holds unknown field(s) {', '.join(unknown[:3])} (a newer weftsim or an edit)")
    missing = [name for name in FORMAT_1_FIELDS.get(cls.__name__, ()) if name in fields and name not in data]
    missing += [name for name, f in fields.items() if name not in data and f.default is dataclasses.MISSING
                and f.default_factory is dataclasses.MISSING and name not in missing]
    if missing:
        raise ValueError(f"{where} lacks field(s) {', '.join(missing[:4])}")
    hints = typing.get_type_hints(cls, vars(params))
    values: dict[str, Any] = {}
    for name, value in data.items():
        nested, optional, hint = _field_type(hints[name])
        at = f"{where}.{name}"
        if value is None and optional:
            values[name] = None
        elif nested is not None:
            values[name] = rebuild(nested, value, at)
        else:
            values[name] = _value(hint, value, at)
    return cls(**values)


def check_scene(path: Path, scene: params.Scene) -> None:
    """The rebuilt scene validated as a scene file is (ranges, laws, assembly), and its wear profiles."""
    from weftsim.input.scene import scene_from_keys, to_file_keys

    try:
        keys = {k: v for k, v in to_file_keys(scene).items() if v is not None}  # None: an optional key not given
        scene_from_keys(keys, "the file's scene")
    except ValueError as exc:
        raise _fail(path, f"its scene is not valid ({exc})") from None
    if scene.geometry.fourbar_branch not in (1, -1):  # the one field a scene file writes as a sign ("+" or "-")
        raise _fail(path, f"its scene's geometry.fourbar_branch must be 1 or -1, got {scene.geometry.fourbar_branch}")
    for joint_name, joint in (("joint", scene.joint), ("joint_f", scene.joint_f)):
        profiles = (joint.bearing_wear, joint.journal_wear)
        if any(profiles) and (len(profiles[0]) != len(profiles[1]) or len(profiles[0]) < 3
                              or not all(math.isfinite(v) and v >= 0.0 for p in profiles for v in p)):
            raise _fail(path, f"its scene's {joint_name} wear profiles must be two lists of equal length (>= 3) of "
                              "finite depths >= 0 (m)")


def read_npz(path: str | os.PathLike):
    """The :class:`weftsim.post.results.RunResult` in ``path``, checked as the module docstring says."""
    from weftsim.post.results import CHANNELS, JOINT_F_CHANNELS, OPTIONAL_GROUPS, RunResult, optional_channels

    path = Path(path)
    all_names = CHANNELS + sum(OPTIONAL_GROUPS, ())
    expected = {"meta"} | {f"{t}/{n}" for t in TABLES for n in all_names}
    archive = open_archive(path, WHAT, "give the result.npz file in it")
    try:
        with archive:
            headers = array_headers(path, archive, expected, WHAT)
            meta = read_meta(path, archive, headers)
            has_f = any(f"{t}/{n}" in headers for t in TABLES for n in JOINT_F_CHANNELS)
            names = CHANNELS + optional_channels(name.partition("/")[2] for name in headers
                                                 if name.startswith("samples/"))
            check_channel_headers(path, headers, names)
            try:
                scene = rebuild(params.Scene, meta["scene"])
            except (ValueError, TypeError) as exc:
                raise _fail(path, f"its scene cannot be rebuilt: {exc}") from None
            check_scene(path, scene)
            if has_f != (not scene.joint_f.is_ideal):
                raise _fail(path, "it holds joint F's channels but its scene has F ideal" if has_f else
                            "its scene gives F a clearance but it holds no joint F channels")
            problem = channels_problem(names, scene)
            if problem:
                raise _fail(path, problem)
            tables: dict[str, dict[str, Any]] = {}
            for table in TABLES:
                tables[table] = {}
                for name in names:
                    tables[table][name] = read_array(archive, f"{table}/{name}")
    except OutputError:
        raise
    except DAMAGE as exc:
        raise _fail(path, f"damaged archive ({type(exc).__name__}: {exc})") from None
    check_times(path, meta, scene, tables)
    try:
        return RunResult(scene, meta["engine"], meta["status"], meta["message"], tables["samples"], tables["steps"],
                         meta["solver_stats"], meta["events"], meta["plausibility"], meta["path"])
    except ValueError as exc:
        raise _fail(path, str(exc)) from None


def channels_problem(names: tuple[str, ...], scene: params.Scene) -> str:
    """What is wrong with a saved result's channel groups against its scene ('' if nothing): every run of a
    scene has exactly :func:`weftsim.post.results.scene_channels` (a lubricated joint's film channels, and only
    a lubricated joint's), so a file edited to drop or add a group is refused, not read as another run."""
    from weftsim.post.results import LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F, scene_channels

    expected = scene_channels(scene)
    for group, table, joint in ((LUBRICATION_CHANNELS, "joint_e", scene.joint),
                                (LUBRICATION_CHANNELS_F, "joint_f", scene.joint_f)):
        has, needs = group[0] in names, group[0] in expected
        if has and not needs:
            state = "ideal" if joint.is_ideal else "dry (no [" + table + ".lubrication])"
            return f"it holds the film channels of {table} ({group[0]}, ...) but its scene's joint is {state}"
        if needs and not has:
            return f"its scene's {table} is lubricated but it holds no film channels ({group[0]}, ...)"
    if set(names) != set(expected):
        return f"its channels are not those of a run of its scene ({', '.join(sorted(set(names) ^ set(expected)))})"
    return ""


def check_times(path: Path, meta: dict, scene: params.Scene, tables: dict) -> None:
    """``time_s`` finite and not decreasing in both tables; a successful run's steps end at the scene's end."""
    for table in TABLES:
        t = np.asarray(tables[table]["time_s"], dtype=float)
        if t.size and not (np.all(np.isfinite(t)) and np.all(np.diff(t) >= 0.0) and t[0] >= 0.0):
            raise _fail(path, f"{table}/time_s is not a time axis (finite, from >= 0, never decreasing)")
    first = meta["events"].get("first_contact_time_s")
    if first is not None and first > scene.drive.end_time * (1.0 + 1e-9):
        raise _fail(path, f"its first contact at {first:.6g} s is after the run's end, {scene.drive.end_time:.6g} s")
    if meta["status"] == "success":
        t = tables["steps"]["time_s"]
        # The last accepted step lands on the end time (both engines); 1e-9 relative is far above its round-off
        # (a few ulp) and far below anything a changed drive.speed or drive.revolutions gives.
        if not t.size or abs(float(t[-1]) - scene.drive.end_time) > 1e-9 * scene.drive.end_time:
            end = f"{float(t[-1]):.6g} s" if t.size else "no step at all"
            raise _fail(path, f"its status is success but its steps end at {end}, not at the scene's end time "
                              f"{scene.drive.end_time:.6g} s (drive.speed and drive.revolutions)")
