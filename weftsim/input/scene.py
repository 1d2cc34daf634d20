"""Scene files: TOML in, validated :class:`weftsim.input.params.Scene` out.

A scene file may ``extends = "other.toml"`` (path relative to the file) or
``extends = "reference"`` (a bundled scene, :func:`bundled_scenes`) and then holds only
what differs; tables merge key by key.  A scene is named by a path or by the name of a
bundled scene (:func:`scene_source`): a regular file at the path wins, so a user's file
is never shadowed by a bundled scene of the same name.  Units live in the key names
(``_mm``, ``_deg``, ``_rpm``, ``_gpa``, ...) and are converted to SI here.  A scene
must give every key of the sections that describe the machine (:data:`REQUIRED_SECTIONS`),
itself or through ``extends``; settings (solver, output, compare, limits) default.  Every
problem is reported as one :class:`SceneError` naming the file, the key, the bad
value and what is allowed.  :data:`SCHEMA` (:mod:`weftsim.input.schema`) is the single list of
keys; the README's scene reference is written from it.
"""

from __future__ import annotations

import difflib
import math
import os
import stat
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

from weftsim.input import params
from weftsim.errors import SceneError
# The schema (weftsim.input.schema), read here and re-exported (SCHEMA, Key, shown, ...) as before.
from weftsim.input.schema import (  # noqa: F401
    _BY_PATH,
    BRANCHES,
    CALLBACK_ROUTES,
    DEG,
    EXPLICIT_METHODS,
    EXUDYN_MODELS,
    GPA,
    IMPACT_VELOCITY_RULES,
    INTEGRATORS,
    LUBRICATION_KEYS,
    MM,
    MPA,
    OPTIONAL,
    REQUIRED,
    REQUIRED_SECTIONS,
    RPM,
    SCHEMA,
    STEP_CONTROLS,
    TOP_LEVEL,
    TREE_SOLVERS,
    WEAR_KEYS,
    Key,
    _set,
    shown,
)
from weftsim.version import package_directory

# A scene file is a few kilobytes (models/reference.toml: 2.5 kB).  Anything beyond this bound
# is not a scene (a log, an image, /dev/zero): it is refused before it is read into memory.
MAX_SCENE_BYTES = 1 << 20
# Longest `extends` chain: the deepest in models/ is 2 files; 64 leaves room for any layering
# a user builds and stops a runaway chain with one line instead of a RecursionError.
MAX_EXTENDS_DEPTH = 64
# The optional table of the flexible rapier tape (docs/rapier-tape.md): given even empty, the scene has a tape.
TAPE_TABLE = "rapier_tape"
# The optional tables that mean something given empty: the tape, the exchange (docs/rapier-tape.md), with defaults.
OPTIONAL_TABLES = {TAPE_TABLE: ("rapier_tape", params.RapierTape), "exchange": ("exchange", params.Exchange)}


def _spelling(table: tuple[str, ...], name: str) -> str:
    """Where a key is written in the file: ``clearance_mm in [joint_e]`` or ``"a.b" at the top level``."""
    key = f'"{name}"' if "." in name else name
    return shown(f"{key} in [{'.'.join(table)}]" if table else f"{key} at the top level")


def _flatten(table: dict, where: str, prefix: tuple[str, ...] = (),
             seen: dict[str, str] | None = None) -> dict[str, Any]:
    """Dotted keys of a TOML table; one key given twice (a quoted dotted key at one level and
    the same key in its table) is a :class:`SceneError` naming both places."""
    seen = {} if seen is None else seen
    flat: dict[str, Any] = {}
    for name, value in table.items():
        path = ".".join(prefix + (name,))
        if isinstance(value, dict):
            if not value and path in OPTIONAL_TABLES:  # an empty [rapier_tape] / [exchange]: its defaults
                flat[path] = {}
            elif not value:
                _check_empty_table(path, where)
            flat.update(_flatten(value, where, prefix + (name,), seen))
            continue
        if path in seen:
            raise SceneError(f"{where}: key '{shown(path)}' is given twice, as {seen[path]} and as "
                             f"{_spelling(prefix, name)}; give it once")
        seen[path] = _spelling(prefix, name)
        flat[path] = value
    return flat


def _tables() -> set[str]:
    """Every table a scene file may hold (``joint_e``, ``joint_e.wear``, ``solver.reference``, ...)."""
    out: set[str] = set()
    for key in SCHEMA:
        parts = key.path.split(".")
        out.update(".".join(parts[:i]) for i in range(1, len(parts)))
    return out


def _check_empty_table(path: str, where: str) -> None:
    """An empty table says something or nothing: ``[joint_e.lubrication]`` with no key would run the dry joint
    (the table needs its viscosity), an unknown one (``[joint_e.lubricaton]``) would be ignored: refused."""
    tables = _tables()
    if path not in tables:
        close = difflib.get_close_matches(path, sorted(tables), n=1, cutoff=0.75)
        mean = f"did you mean [{close[0]}]? " if close else ""
        raise SceneError(f"{where}: unknown table [{shown(path)}]; {mean}a scene's tables are "
                         f"{', '.join(sorted(t for t in tables if '.' not in t))} and the tables in them")
    if path.endswith(".lubrication"):
        raise SceneError(f"{where}: the table [{path}] is empty; it must give the oil's viscosity "
                         f"({path}.viscosity_mpa_s, the other lubrication keys default), or leave the table out "
                         "for the dry joint")


def _read_toml(path: Path) -> dict:
    """The TOML table of one scene file: a regular file of at most :data:`MAX_SCENE_BYTES`.

    Checked with ``stat`` before opening, so a FIFO (which would block) or a device such as
    ``/dev/zero`` (which never ends) is refused without being read.
    """
    try:
        info = path.stat()
    except FileNotFoundError:
        raise SceneError(f"{path}: scene file not found") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot be read ({exc.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        raise SceneError(f"{path}: is a directory, expected a scene file (.toml)")
    if not stat.S_ISREG(info.st_mode):
        raise SceneError(f"{path}: is not a regular file (a pipe, device or socket); a scene must be a "
                         "regular .toml file")
    if info.st_size > MAX_SCENE_BYTES:
        raise SceneError(f"{path}: is {info.st_size} bytes, more than a scene file's {MAX_SCENE_BYTES} "
                         "bytes; a scene file holds only keys and values (.toml)")
    try:
        with path.open("rb") as file:
            data = file.read(MAX_SCENE_BYTES + 1)  # bounded even if the file grows after the stat
        if len(data) > MAX_SCENE_BYTES:
            raise SceneError(f"{path}: grew beyond a scene file's {MAX_SCENE_BYTES} bytes while being read")
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot be read ({exc})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc})") from None


def bundled_directory() -> Path | None:
    """The directory of the bundled scene files, or None if this installation has none.

    An installed weftsim carries them as the package data ``weftsim/scenes`` (the build maps
    the repository's ``models/`` there, see ``setup.py``); a source checkout, run from the tree
    or installed in editable mode, reads ``models/`` beside the package itself.
    """
    package = package_directory()
    installed, checkout = package / "scenes", package.parent / "models"
    if (installed / "reference.toml").is_file():
        return installed
    if (checkout / "reference.toml").is_file() and (package.parent / "pyproject.toml").is_file():
        return checkout
    return None


def bundled_scenes() -> list[str]:
    """Names of the bundled scenes, sorted: the file's path below the scene directory without ``.toml``
    (``"reference"``, ``"paper/clearance_0p50mm_400rpm"``)."""
    root = bundled_directory()
    if root is None:
        return []
    return sorted(p.relative_to(root).with_suffix("").as_posix() for p in root.rglob("*.toml") if p.is_file())


def bundled_scene_path(name: str) -> Path:
    """The file of the bundled scene ``name``.

    Raises
    ------
    SceneError
        If no bundled scene has that name (the message lists them, closest first).
    """
    names = bundled_scenes()
    if name not in names:
        raise SceneError(f"no bundled scene named {shown(name)!r}; {_bundled_hint(name, names)}")
    root = bundled_directory()
    assert root is not None  # names is not empty
    return root / (name + ".toml")


def _bundled_hint(name: str, names: list[str]) -> str:
    """'did you mean ...? bundled scenes: ...' for an unknown scene name."""
    if not names:
        return "this installation has no bundled scenes"
    near = difflib.get_close_matches(name.removesuffix(".toml"), names, n=2, cutoff=0.6)
    mean = f"did you mean {' or '.join(near)}? " if near else ""
    return f"{mean}bundled scenes: {', '.join(names)} ('weftsim scenes' lists them)"


def scene_source(scene: str | os.PathLike, base: Path | None = None) -> Path:
    """The file a scene argument names: a path, or the name of a bundled scene.

    A string names a regular file if one exists at that path (relative to ``base``, default the
    current directory); otherwise a bundled scene of that name (``"reference"``,
    ``"paper/clearance_0p50mm_400rpm"``).  A :class:`os.PathLike` is always a path.  Anything else
    is returned as a path, so reading it reports what is wrong (not found, a directory, a pipe).

    Raises
    ------
    SceneError
        If nothing exists at the path and no bundled scene has that name.
    """
    if not isinstance(scene, (str, os.PathLike)):
        raise SceneError(f"a scene is a path or the name of a bundled scene, got {type(scene).__name__} "
                         f"{shown(repr(scene))[:80]}")
    path = Path(scene) if base is None else base / scene
    if isinstance(scene, os.PathLike) or path.is_file():
        return path
    if scene in bundled_scenes():
        return bundled_scene_path(scene)
    if os.path.lexists(path):  # a directory, pipe or device: reading it says so
        return path
    raise SceneError(f"{shown(str(path))}: scene file not found, and no bundled scene has that name; "
                     f"{_bundled_hint(scene, bundled_scenes())}")


def scene_description(path: Path) -> str:
    """The ``description`` of a scene file (empty if it gives none or cannot be read)."""
    try:
        description = _read_toml(path).get("description", "")
    except SceneError:
        return ""
    return description if isinstance(description, str) else ""


def _read_merged(path: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """Flattened keys of a scene and its ``extends`` chain, and the file each key came from.

    The chain is followed in a loop (not by recursion), at most :data:`MAX_EXTENDS_DEPTH` files.
    """
    chain: list[tuple[Path, dict[str, Any]]] = []
    path = path.resolve()
    while True:
        if path in [p for p, _ in chain]:
            raise SceneError(f"{path}: 'extends' loops back to itself via {[str(p) for p, _ in chain]}")
        if len(chain) == MAX_EXTENDS_DEPTH:
            raise SceneError(f"{chain[0][0]}: the 'extends' chain is longer than {MAX_EXTENDS_DEPTH} files "
                             f"(reached {path}); a scene may extend at most {MAX_EXTENDS_DEPTH} files deep")
        flat = _flatten(_read_toml(path), str(path))
        chain.append((path, flat))
        if "extends" not in flat:
            break
        parent = flat.pop("extends")
        if not isinstance(parent, str):
            raise SceneError(f"{path}: key 'extends' must be a path or the name of a bundled scene, got {parent!r}")
        try:
            path = scene_source(parent, path.parent).resolve()
        except SceneError as exc:
            raise SceneError(f"{path}: key 'extends' = {shown(repr(parent))}: {exc}") from None
    merged: dict[str, Any] = {}
    origin: dict[str, Any] = {}
    for index, (path, flat) in enumerate(reversed(chain)):
        if index:  # a base file's name and description do not describe the scene extending it
            merged.pop("name", None)
            merged.pop("description", None)
        merged.update(flat)
        origin.update({key: path for key in flat})
    return merged, origin


def _plain(value: Any) -> Any:
    """A numpy scalar or array as the Python value it holds (``np.float32(0.3)`` -> 0.3, an array -> a list):
    a script's override computed with numpy is a number like any other."""
    if type(value).__module__ == "numpy" and hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _convert(key: Key, value: Any, where: str) -> Any:
    value = _plain(value)

    def fail(expect: str) -> SceneError:
        return SceneError(f"{where}: key '{key.path}' {expect}, got {value!r}")

    if key.kind == "bool":
        if not isinstance(value, bool):
            raise fail("must be true or false")
        return value
    if key.kind == "str":
        if not isinstance(value, str):
            raise fail("must be a string")
        if key.choices and value not in key.choices:
            raise fail(f"must be {key.allowed()}")
        return value
    if key.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise fail("must be a whole number")
        numbers = [value]
    elif key.kind == "float":
        numbers = [value]
    else:
        size = {"floats2": 2, "floats3": 3}[key.kind]
        if not isinstance(value, list) or len(value) != size:
            raise fail(f"must be a list of {size} numbers")
        numbers = value
    for number in numbers:
        if isinstance(number, bool) or not isinstance(number, (int, float)):
            raise fail("must be a number")
        try:
            finite = math.isfinite(number) and math.isfinite(float(number) * key.scale)
        except OverflowError:  # an integer beyond any float
            finite = False
        if not finite:
            raise fail("must be a finite number (also in SI units)")
        low_bad = key.low is not None and (number <= key.low if key.low_open else number < key.low)
        high_bad = key.high is not None and (number >= key.high if key.high_open else number > key.high)
        if low_bad or high_bad:
            raise fail(f"must be {key.allowed()}")
    if key.target in ("joint.friction_velocities", "joint_f.friction_velocities") and not numbers[0] < numbers[1]:
        # Checked here, not with the other cross-key checks: ClearanceJoint itself refuses v0 >= v1.
        raise fail("must have v0 < v1")
    if key.target in ("joint.design_clearance", "joint_f.design_clearance") and not numbers[0] < numbers[1]:
        raise fail("must be [low, high] with low < high")
    if key.kind == "int":
        return value
    scaled = tuple(float(n) * key.scale for n in numbers)
    return scaled[0] if key.kind == "float" else scaled


def _set_checked(scene: params.Scene, target: str, value: Any, where: str) -> params.Scene:
    """:func:`_set`, with a cross-field refusal of the parameter objects (ValueError) as a SceneError."""
    try:
        return _set(scene, target, value)
    except ValueError as exc:
        raise SceneError(f"{where}: {exc}") from None


LUBRICATION_TABLES = (("joint_e", "joint"), ("joint_f", "joint_f"))


# The keys that name the lubricant of a [<joint>.lubrication] table: a fixed viscosity, or an oil; and every key
# that matters only with an oil (its properties and the heat balance's).
VISCOSITY_KEY, OIL_KEYS = "viscosity_mpa_s", ("oil", "oil.nu40_mm2_s", "oil.nu100_mm2_s")
HEAT_KEYS = OIL_KEYS + ("oil.density_kg_m3", "oil.heat_capacity_j_kg_k", "ambient_temperature_c",
                        "housing_heat_transfer_w_k", "oil_supply")


def _names_oil(flat: dict, prefix: str) -> bool:
    return any(flat.get(prefix + k) not in (None, "", 0, 0.0) for k in OIL_KEYS)


def _check_lubrication_given(flat: dict, where: str, before: params.Scene | None = None) -> None:
    """A ``[<joint>.lubrication]`` table must name its lubricant, ``viscosity_mpa_s`` or an ``oil``, not both
    (``before``: the scene overridden, whose film may already name it).  ``flat``: the keys given, file values."""
    for table, attr in LUBRICATION_TABLES:
        prefix = f"{table}.lubrication."
        oil, viscosity = _names_oil(flat, prefix), flat.get(prefix + VISCOSITY_KEY) not in (None, 0, 0.0)
        if oil and viscosity:
            raise SceneError(f"{where}: keys '{prefix}{VISCOSITY_KEY}' and '{prefix}oil' are both given: give the "
                             "oil (its viscosity then follows from the film temperature) or a fixed viscosity, not "
                             "both")
        if before is not None and getattr(before, attr).lubrication is not None:
            continue
        if any(k.startswith(prefix) for k in flat) and not (oil or prefix + VISCOSITY_KEY in flat):
            raise SceneError(f"{where}: missing required key '{prefix}{VISCOSITY_KEY}' or '{prefix}oil'; a "
                             f"[{table}.lubrication] table must give the oil's viscosity or name the oil (the other "
                             "lubrication keys default)")


def _switch_lubricant(flat: dict, overrides: dict) -> None:
    """An override naming the lubricant replaces the file's: ``--set ...oil=...`` drops the file's
    ``viscosity_mpa_s`` and ``--set ...viscosity_mpa_s=...`` its oil (``flat`` is changed in place)."""
    for table, _ in LUBRICATION_TABLES:
        prefix = f"{table}.lubrication."
        if _names_oil(overrides, prefix) and prefix + VISCOSITY_KEY not in overrides:
            flat.pop(prefix + VISCOSITY_KEY, None)
        if prefix + VISCOSITY_KEY in overrides and not _names_oil(overrides, prefix):
            for key in OIL_KEYS:
                flat.pop(prefix + key, None)


def _check_scene(scene: params.Scene, where: str, origin: dict[str, Path]) -> None:
    """Cross-key checks: law names, clearance below the journal radius, linkage assembly."""
    from weftsim.joint.contact import LAWS

    def at(key: str) -> str:
        return str(origin.get(key, where))

    for table, joint in (("joint_e", scene.joint), ("joint_f", scene.joint_f)):
        if table == "joint_f" and joint.is_ideal:
            continue  # the ideal joint at F: its other keys describe nothing
        law, clearance = f"{table}.law", f"{table}.clearance_mm"
        if joint.law not in LAWS:
            raise SceneError(f"{at(law)}: key '{law}' must be one of {', '.join(sorted(LAWS))}, got {joint.law!r}")
        if joint.clearance >= joint.journal_radius:
            raise SceneError(
                f"{at(clearance)}: key '{clearance}' must be smaller than the journal radius "
                f"{joint.journal_radius / MM:g} mm, got {joint.clearance / MM:g}"
            )
    if scene.output.sample_angle / scene.drive.speed > scene.drive.end_time:
        raise SceneError(f"{at('drive.revolutions')}: key 'drive.revolutions' is shorter than one output sample")
    from weftsim.mechanism.kinematics import assembly_failure_angle

    angle = assembly_failure_angle(scene.geometry)
    if angle is not None:
        raise SceneError(
            f"{where}: the linkage cannot be assembled at crank angle {math.degrees(angle):.2f} deg "
            "(the four-bar O-E-F-G does not close: check mechanism.l_oe_mm, l_ef_mm, l_fg_mm, l_og_mm "
            "and rocker_arm_angle_deg)"
        )
    if scene.exchange is not None:
        from weftsim.mechanism.kinematics import linkage_state

        explicit = scene.rapier_tape is not None and scene.rapier_tape.model == "flexible"  # "auto": at the run
        problem = params.exchange_problem(scene, float(linkage_state(math.pi, scene.geometry).rapier_displacement),
                                          explicit)
        if problem:
            key = problem.split("'")[1]
            raise SceneError(f"{at(key)}: {problem}")
    if scene.rapier_tape is not None:
        from weftsim.mechanism.kinematics import rapier_stroke

        tape = scene.rapier_tape
        longest = tape.free_length + rapier_stroke(scene.geometry)
        if tape.length < longest * (1.0 - 1e-12):  # the tape cannot run out of the wheel
            raise SceneError(f"{at('rapier_tape.length_mm')}: key 'rapier_tape.length_mm' must be at least "
                             f"free_length_mm + the stroke = {longest * 1e3:.1f} mm (the tape cannot run out of the "
                             f"wheel), got {tape.length * 1e3:g}")


def _known(path: str, where: str) -> Key:
    """The schema key of a dotted path, or a SceneError listing the keys allowed there."""
    key = _BY_PATH.get(path)
    if key is None:
        section = path.rpartition(".")[0]
        near = [k.path for k in SCHEMA if k.path.rpartition(".")[0] == section] or sorted(
            {k.path.partition(".")[0] for k in SCHEMA}
        )
        close = difflib.get_close_matches(path, list(_BY_PATH), n=1, cutoff=0.75)
        mean = f"did you mean '{close[0]}'? " if close else ""
        raise SceneError(f"{where}: unknown key '{shown(path)}'; {mean}allowed here: {', '.join(near)}")
    return key


def scene_from_keys(flat: dict[str, Any], where: str = "scene", origin: dict[str, Path] | None = None) -> params.Scene:
    """Validated :class:`Scene` from flattened dotted keys (file values, file units)."""
    from weftsim.input.joint_keys import inherit_joint_f

    origin = dict(origin or {})
    flat, inherited = inherit_joint_f(flat)
    origin.update({"joint_f." + rest: origin["joint_e." + rest] for rest in inherited if "joint_e." + rest in origin})
    name = flat.get("name", "scene")
    if not isinstance(name, str):
        raise SceneError(f"{where}: key 'name' must be a string, got {name!r}")
    if not name or not name.isprintable():  # it heads every report line and figure title
        raise SceneError(f"{where}: key 'name' must be a non-empty line of printable characters "
                         f"(no newline or escape sequence), got {name!r}")
    scene = params.Scene(name=name, source=where)
    # Every key against its own type and range first, then the checks between keys: a value past its bound is
    # named as that (oil.nu40_mm2_s = 1e6 beside a viscosity_mpa_s was reported as "both given").
    converted = {}
    for path, value in flat.items():
        if path in TOP_LEVEL or path in OPTIONAL_TABLES:
            continue
        src = str(origin.get(path, where))
        key = _known(path, src)
        converted[path] = key, _convert(key, value, src), src
    _check_lubrication_given(flat, where)
    for path in flat:
        if path in OPTIONAL_TABLES:  # an empty [rapier_tape] or [exchange] table (_flatten)
            attribute, table = OPTIONAL_TABLES[path]
            scene = replace(scene, **{attribute: getattr(scene, attribute) or table()})
            continue
        if path not in converted:
            continue
        key, value, src = converted[path]
        if key.path == "mechanism.fourbar_branch":
            value = BRANCHES[value]
        scene = _set_checked(scene, key.target, value, src)
    scene = replace(scene, joint_f_inherits=inherited)
    _check_scene(scene, where, origin)
    return _film_temperature(scene, where)


def _film_temperature(scene: params.Scene, where: str) -> params.Scene:
    """``scene`` with each oiled joint's viscosity at its film temperature
    (:func:`weftsim.joint.bearing.resolve_scene`); a heat balance without a solution is a SceneError naming ``where``."""
    from weftsim.joint.bearing import resolve_scene

    try:
        return resolve_scene(scene)
    except SceneError as exc:
        raise SceneError(f"{where}: {exc}") from None


def load_scene(path: str | os.PathLike, overrides: dict[str, Any] | None = None,
               overrides_from: str = "command line", *, refuse_ideal_keys: bool = True) -> params.Scene:
    """Read, merge (``extends``), override and validate a scene file.

    Joint F given a clearance takes every key of ``[joint_e]`` its table does not give
    (:func:`weftsim.input.joint_keys.inherit_joint_f`); ``scene.joint_f_inherits`` names them.

    Parameters
    ----------
    path : str or path-like
        The TOML scene file, or the name of a bundled scene (:func:`scene_source`).
    overrides : dict, optional
        Dotted file keys with file-unit values, e.g. ``{"drive.speed_rpm": 500}``,
        applied after the file (the command-line flags use this).
    overrides_from : str
        Where the overrides came from, as error messages name it.
    refuse_ideal_keys : bool
        Refuse an override of a joint key (other than its ``clearance_mm``) at a joint that is ideal
        in the resulting scene: it would change nothing (:mod:`weftsim.input.joint_keys`).  A sweep passes
        False and checks its cells together.

    Raises
    ------
    SceneError
        Naming the file (or "command line"), the key, the bad value and what is allowed;
        or the required keys (sections :data:`REQUIRED_SECTIONS`) that neither the file
        nor the files it extends give; or a joint key set on a joint that is ideal.
    """
    from weftsim.input.joint_keys import describes_joint, ideal_joint_keys, ideal_key_message

    path = scene_source(path)
    flat, origin = _read_merged(path)
    flat.setdefault("name", path.stem)
    _switch_lubricant(flat, {k: v for k, v in (overrides or {}).items() if v is not None})
    for dotted, value in (overrides or {}).items():
        if value is None:
            continue
        flat[dotted] = value
        origin[dotted] = Path(overrides_from)
    for dotted in flat:  # a misspelt key is reported as such, not as the missing one it stands for
        if dotted not in TOP_LEVEL and dotted not in OPTIONAL_TABLES:
            _known(dotted, str(origin.get(dotted, path)))
    if "joint_f.clearance_mm" not in flat:  # a [joint_f] table without a clearance describes an ideal joint
        stray = [key for key in flat if key.startswith("joint_f.") and describes_joint(key)
                 and key not in (overrides or {})]  # overrides: checked on the scene below
        if stray:
            raise SceneError(ideal_key_message(stray[0], str(origin.get(stray[0], path))))
    missing = [key for key in REQUIRED if key not in flat]
    if missing:
        raise SceneError(
            f"{path}: missing required keys {', '.join(missing)}; a scene must give every key of "
            f"[{'], ['.join(REQUIRED_SECTIONS)}] itself or through `extends = \"reference.toml\"` "
            "(then it holds only what differs)"
        )
    scene = scene_from_keys(flat, str(path), origin)
    given = [key for key, value in (overrides or {}).items() if value is not None]
    idle = ideal_joint_keys(scene, given) if refuse_ideal_keys else []
    if idle:
        raise SceneError(ideal_key_message(idle[0], overrides_from))
    return scene


def _file_value(si: float, scale: float) -> float:
    """``si / scale`` as the file gives it: 30 deg, not the 29.999999999999996 the division leaves of 30 * pi / 180,
    when the 15-digit value scales back to exactly ``si`` (otherwise the quotient, unrounded)."""
    value = si / scale
    if scale == 1.0 or not math.isfinite(value):
        return value
    short = float(f"{value:.15g}")
    return short if short * scale == si else value


def to_file_keys(scene: params.Scene) -> dict[str, Any]:
    """The scene as flattened file keys in file units (for summaries and provenance)."""
    out: dict[str, Any] = {"name": scene.name}
    for key in SCHEMA:
        obj: Any = scene
        for part in key.target.split("."):
            obj = getattr(obj, part)
            if obj is None:
                break  # a dry joint's lubrication keys: None, as any unset optional key
        if obj is None:  # an optional key the scene does not give
            pass
        elif key.path.endswith(".lubrication." + VISCOSITY_KEY) and _lubrication_of(scene, key).has_oil:
            continue  # the viscosity follows from the oil (at the film temperature): the oil's keys say it
        elif key.path == "mechanism.fourbar_branch":
            obj = "+" if obj > 0 else "-"
        elif key.kind in ("float", "floats2", "floats3"):
            obj = _file_value(obj, key.scale) if key.kind == "float" else [_file_value(v, key.scale) for v in obj]
        out[key.path] = obj
    return out


def _lubrication_of(scene: params.Scene, key: Key) -> params.Lubrication:
    return getattr(scene, key.target.partition(".")[0]).lubrication


def apply_overrides(scene: params.Scene, overrides: dict[str, Any], where: str = "command line",
                    refuse_ideal_keys: bool = True) -> params.Scene:
    """``scene`` with dotted file keys replaced (file units), validated as :func:`load_scene` validates.

    The same scene :func:`load_scene` gives for a file and these overrides, without reading
    the file again: a sweep validates thousands of cells against one base scene this way.

    Keys joint F takes from joint E follow E's overrides (:func:`weftsim.input.joint_keys.resync_joint_f`).

    Raises
    ------
    SceneError
        For an unknown key, a bad value or a scene that fails the cross-key checks, naming ``where``;
        with ``refuse_ideal_keys``, for a joint key set on a joint that is ideal (it changes nothing).
    """
    from weftsim.input.joint_keys import ideal_joint_keys, ideal_key_message, resync_joint_f

    before = scene
    given = {k: v for k, v in overrides.items() if v is not None}
    scene = _switched_scene(scene, given)
    for dotted, value in overrides.items():
        if value is None:
            continue
        if dotted == "name":
            if not isinstance(value, str):
                raise SceneError(f"{where}: key 'name' must be a string, got {value!r}")
            scene = replace(scene, name=value)
            continue
        key = _known(dotted, where)
        value = _convert(key, value, where)
        if key.path == "mechanism.fourbar_branch":
            value = BRANCHES[value]
        scene = _set_checked(scene, key.target, value, where)
    scene = resync_joint_f(scene, {key for key, value in overrides.items() if value is not None})
    _check_lubrication_given(given, where, before)
    _check_scene(scene, where, {})
    idle = ideal_joint_keys(scene, [key for key, value in overrides.items() if value is not None])
    if idle and refuse_ideal_keys:
        raise SceneError(ideal_key_message(idle[0], where))
    return _film_temperature(scene, where)


def _switched_scene(scene: params.Scene, given: dict[str, Any]) -> params.Scene:
    """``scene`` ready for ``given`` overrides: an override naming an oil clears a fixed viscosity, one giving
    ``viscosity_mpa_s`` clears the oil (:func:`_switch_lubricant` on a scene)."""
    for table, attr in LUBRICATION_TABLES:
        prefix = f"{table}.lubrication."
        lub = getattr(scene, attr).lubrication
        if lub is None:
            continue
        if _names_oil(given, prefix) and prefix + VISCOSITY_KEY not in given:
            lub = replace(lub, viscosity=0.0, film_temperature=None)
        elif prefix + VISCOSITY_KEY in given and not _names_oil(given, prefix):
            lub = replace(lub, oil="", oil_nu40=0.0, oil_nu100=0.0, film_temperature=None)
        scene = replace(scene, **{attr: replace(getattr(scene, attr), lubrication=lub)})
    return scene
