"""Sweep grids: ``--vary KEY=VALUES`` parsing, short key names and the cells of a grid.

A sweep varies some scene keys over lists of values; every combination (the
Cartesian product) is one *cell*, i.e. one scene run.  Values are given in the
scene file's units (``clearance_mm=0.25``), as a list ``a,b,c`` or as an
inclusive range ``start:stop:count`` (``speed_rpm=300:800:6`` is 300, 400, ...,
800).  Keys are the dotted scene keys of :data:`weftsim.input.scene.SCHEMA` or their
short names (the last dotted part where it is unique: ``clearance_mm``,
``speed_rpm``, ``law``, ``revolutions``, ``restitution``, ...).

Each cell is named by its parameters, sorted by short name, e.g.
``clearance_mm=0.25,speed_rpm=400``; that name is its result directory.
"""

from __future__ import annotations

import collections
import difflib
import itertools
import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from weftsim.errors import SweepError
from weftsim.input.scene import SCHEMA, Key

SWEEPABLE_KINDS = ("float", "int", "str", "bool")
LIST_SIZES = {"floats2": 2, "floats3": 3}  # list-valued keys: --set only (a comma separates --vary values)
RANGE_DIGITS = 12  # range values are rounded to 12 significant digits: 0.08, not 0.08000000000000002
COMMON_KEYS = ("clearance_mm", "speed_rpm", "law", "revolutions", "restitution", "friction_coefficient")
SAFE_TEXT = re.compile(r"^[A-Za-z0-9_.+-]+$")  # string values must be usable in a directory name


def _short_names() -> dict[str, Key]:
    """Short name (last dotted part) -> key, for the parts that occur once in the schema.

    Joint F's keys repeat joint E's: they go by their full path, and E's keep the short names.
    """
    by_last: dict[str, list[Key]] = {}
    for key in SCHEMA:
        if key.path.startswith("joint_f."):
            continue
        by_last.setdefault(key.path.rpartition(".")[2], []).append(key)
    return {name: keys[0] for name, keys in by_last.items() if len(keys) == 1}


SHORT_NAMES: dict[str, Key] = _short_names()
_BY_PATH: dict[str, Key] = {key.path: key for key in SCHEMA}


def short_name(key: Key) -> str:
    """The name a key goes by in cell names and tables: its short name if it has one, else the dotted path."""
    last = key.path.rpartition(".")[2]
    return last if SHORT_NAMES.get(last) is key else key.path


def resolve_key(name: str) -> Key:
    """The schema key for a short name or a full dotted scene key.

    Raises
    ------
    SweepError
        For unknown or ambiguous names, with close matches and the list of short names.
    """
    if name in _BY_PATH:
        return _BY_PATH[name]
    if name in SHORT_NAMES:
        return SHORT_NAMES[name]
    ambiguous = [key.path for key in SCHEMA if key.path.rpartition(".")[2] == name
                 and not key.path.startswith("joint_f.")]
    if ambiguous:
        raise SweepError(f"sweep key '{name}' is ambiguous; use the full scene key: {', '.join(ambiguous)}")
    near = difflib.get_close_matches(name, list(SHORT_NAMES) + list(_BY_PATH), n=3)
    hint = f"did you mean {', '.join(near)}? " if near else ""
    raise SweepError(
        f"unknown scene key '{name}'; {hint}use a dotted scene key (any key of the README's scene reference, "
        f"e.g. joint_e.clearance_mm) or its last part where that is unique ({', '.join(COMMON_KEYS)}, ...)"
    )


def format_value(value: Any) -> str:
    """Text of a value in a cell name: shortest exact form, whole floats without '.0' (400.0 -> '400')."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value) if isinstance(value, float) else str(value)


def _scalar(key: Key, text: str, flag: str) -> Any:
    """One value in the key's type (file units); range checks are left to the scene validation."""
    text = text.strip()
    try:
        if key.kind == "float":
            return float(text)
        if key.kind == "int":
            return int(text)
    except ValueError:
        kind = "number" if key.kind == "float" else "whole number"
        raise SweepError(f"{flag}: '{key.path}' takes a {kind}, got {text!r}") from None
    if key.kind == "bool":
        if text.lower() not in ("true", "false"):
            raise SweepError(f"{flag}: '{key.path}' takes true or false, got {text!r}")
        return text.lower() == "true"
    if not SAFE_TEXT.match(text):
        spaced = text.replace(" ", "_")
        hint = f" (for a name with spaces write _: {spaced!r})" if " " in text and SAFE_TEXT.match(spaced) else ""
        raise SweepError(f"{flag}: value {text!r} of '{key.path}' may hold only letters, digits and _ . + -{hint}")
    return text


def _range(key: Key, text: str, flag: str) -> list[Any]:
    """``start:stop:count`` -> count values evenly spaced from start to stop, both included."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SweepError(f"{flag}: a range is start:stop:count (e.g. 300:800:6), got {text!r}")
    if key.kind not in ("float", "int"):
        raise SweepError(f"{flag}: '{key.path}' is not numeric, give a list (a,b,c) instead of a range")
    start, stop = (float(_scalar(key, p, flag)) for p in parts[:2])
    try:
        count = int(parts[2])
    except ValueError:
        raise SweepError(f"{flag}: the count of a range must be a whole number, got {parts[2]!r}") from None
    if count < 2:
        raise SweepError(f"{flag}: a range needs a count of at least 2, got {count} (give one value as a list)")
    values = [float(f"{v:.{RANGE_DIGITS}g}") for v in np.linspace(start, stop, count)]
    if key.kind == "int":
        if any(not v.is_integer() for v in values):
            raise SweepError(f"{flag}: range {text!r} of whole-number key '{key.path}' gives non-whole values")
        return [int(v) for v in values]
    return values


def parse_values(key: Key, text: str, flag: str = "--vary") -> list[Any]:
    """Values of ``text``: a list ``a,b,c`` or an inclusive range ``start:stop:count``."""
    if key.kind not in SWEEPABLE_KINDS:
        size = LIST_SIZES[key.kind]
        raise SweepError(f"{flag}: '{key.path}' holds a list of {size} numbers and cannot be swept; set it for "
                         f"every cell with --set {key.path}={','.join(['X'] * size)}")
    if not text.strip():
        raise SweepError(f"{flag}: no values given for '{key.path}'")
    values = _range(key, text, flag) if ":" in text else [_scalar(key, t, flag) for t in text.split(",")]
    counts = collections.Counter(format_value(v) for v in values)  # linear: a range may hold a million values
    repeated = sorted(name for name, count in counts.items() if count > 1)
    if repeated:
        raise SweepError(f"{flag}: value(s) {', '.join(repeated)} of '{key.path}' given more than once")
    return values


def _split(text: str, flag: str) -> tuple[str, str]:
    name, sep, values = text.partition("=")
    if not sep or not name.strip():
        raise SweepError(f"{flag}: expected KEY=VALUES (e.g. clearance_mm=0.01,0.25,0.5), got {text!r}")
    return name.strip(), values


@dataclass(frozen=True)
class Axis:
    """One varied key: its schema path, the name used in cell names, and its values (file units)."""

    key: str
    name: str
    values: tuple


def value_count(text: str) -> int:
    """How many values ``KEY=VALUES`` gives, read from the text without building them (a range's
    count, a list's items); 1 where the text is malformed, which :func:`parse_vary` then reports."""
    values = text.partition("=")[2]
    if ":" in values:
        parts = values.split(":")
        try:
            return max(int(parts[2]), 1) if len(parts) == 3 else 1
        except ValueError:
            return 1
    return values.count(",") + 1


def parse_vary(text: str) -> Axis:
    """``KEY=VALUES`` -> :class:`Axis`."""
    name, values = _split(text, "--vary")
    key = resolve_key(name)
    return Axis(key.path, short_name(key), tuple(parse_values(key, values, f"--vary {name}")))


def _number_list(key: Key, text: str, flag: str) -> list[float]:
    """``v0,v1`` of a list-valued key (``friction_velocities_m_s``): its numbers; sizes checked here."""
    size = LIST_SIZES[key.kind]
    inner = text.strip()
    if inner.startswith("[") and inner.endswith("]"):  # the TOML form a scene file writes: [1e-4, 2e-4]
        inner = inner[1:-1]
    parts = [part.strip() for part in inner.split(",")]
    if len(parts) != size:
        raise SweepError(f"{flag}: '{key.path}' takes a list of {size} numbers separated by commas "
                         f"(e.g. {key.path}={','.join(['1e-4', '2e-4', '1e-3'][:size])}), got {text!r}")
    try:
        return [float(part) for part in parts]
    except ValueError:
        raise SweepError(f"{flag}: '{key.path}' takes {size} numbers, got {text!r}") from None


def parse_set(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` (a fixed override for every cell) -> (dotted key, value).

    A list-valued key takes its numbers separated by commas (``friction_velocities_m_s=1e-4,2e-4``).
    """
    name, value = _split(text, "--set")
    key = resolve_key(name)
    if key.kind in LIST_SIZES:
        return key.path, _number_list(key, value, f"--set {name}")
    values = parse_values(key, value, f"--set {name}")
    if len(values) != 1:
        raise SweepError(f"--set {name}: takes one value, got {len(values)} (use --vary to sweep it)")
    return key.path, values[0]


@dataclass(frozen=True)
class Cell:
    """One grid point: its directory name, its parameters by name and its scene overrides by dotted key."""

    name: str
    params: dict
    overrides: dict


def cell_name(params: dict[str, Any]) -> str:
    """``clearance_mm=0.25,speed_rpm=400``: parameters sorted by name, so flag order does not matter."""
    return ",".join(f"{name}={format_value(params[name])}" for name in sorted(params))


def grid_size(axes: list[Axis] | tuple[Axis, ...]) -> int:
    """Number of cells of the product of the axes, computed without building them."""
    return math.prod(len(axis.values) for axis in axes)


def grid_cells(axes: list[Axis] | tuple[Axis, ...], fixed: dict[str, Any] | None = None) -> list[Cell]:
    """All cells of the product of the axes (first axis outermost), each with ``fixed`` overrides added.

    Raises
    ------
    SweepError
        If a key is varied twice or both varied and fixed.
    """
    fixed = dict(fixed or {})
    keys = collections.Counter(axis.key for axis in axes)
    twice = sorted(k for k, count in keys.items() if count > 1)
    if twice:
        raise SweepError(f"--vary: key(s) {', '.join(twice)} given more than once; put all values in one --vary")
    both = sorted(set(keys) & set(fixed))
    if both:
        raise SweepError(f"key(s) {', '.join(both)} both varied (--vary) and fixed (--set)")
    if not axes:
        raise SweepError("a sweep needs at least one --vary KEY=VALUES")
    cells = []
    for combo in itertools.product(*(axis.values for axis in axes)):
        params = {axis.name: value for axis, value in zip(axes, combo)}
        overrides = {**fixed, **{axis.key: value for axis, value in zip(axes, combo)}}
        cells.append(Cell(cell_name(params), params, overrides))
    return cells
