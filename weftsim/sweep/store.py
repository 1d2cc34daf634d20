"""The sweep directory: its manifest (``sweep.json``) and the table rebuilt from the cells.

Layout::

    OUT/sweep.json                        base scene, engine, varied keys and values
    OUT/sweep.lock                        while a sweep runs: who holds the directory (weftsim.sweep.lock)
    OUT/<cell name>/cell.json             one per cell, written last (see weftsim.sweep.cell)
    OUT/<cell name>/summary.json, channels.csv[, channels.png, error.txt]
    OUT/sweep.csv                         one row per cell, rebuilt from the cell.json files
    OUT/sweep.png                         peaks across the grid (1-D lines or 2-D heat maps)

Compatibility rule: a directory holds one sweep, defined by the base scene's content
(after ``--set``), the engine and the *set* of varied keys.  Running again with the same
three and other values extends it (cells already finished are reused; the table covers
every cell on disk); anything else is refused, and a non-empty directory without
``sweep.json`` is refused too, so results never mix silently.
"""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

from weftsim.post.record import command_line
from weftsim.version import __version__
from weftsim.sweep.cell import METRIC_CHANNELS, finite_or_none, read_record
from weftsim.sweep.grid import Axis, SweepError, format_value
from weftsim.sweep.lock import LOCK_FILE

if TYPE_CHECKING:
    import xarray

SWEEP_FILE = "sweep.json"
TABLE_FILE = "sweep.csv"
SWEEP_FORMAT = "weftsim-sweep/1"
MAX_MANIFEST_BYTES = 256 * 2**20  # not read into memory beyond this

METRIC_COLUMNS = tuple(
    [f"{c}_rev1_peak" for c in METRIC_CHANNELS]
    + [f"{c}_last_peak" for c in METRIC_CHANNELS]
    + [f"{c}_p99" for c in METRIC_CHANNELS]
)
INFO_COLUMNS = ("status", "wall_time_s", "complete_revolutions", "last_revolution", "first_contact_deg")
# What an axis may be called: a short name or a dotted scene key (grid.short_name), never a column of the table.
SAFE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")
RESERVED_NAMES = frozenset(("cell", "error", *INFO_COLUMNS, *METRIC_COLUMNS))


def manifest(scene_path: str, base_keys: dict, fixed: dict, engine: str, axes: list[Axis]) -> dict[str, Any]:
    """The content of ``sweep.json`` for a planned sweep."""
    return {
        "format": SWEEP_FORMAT,
        "scene_path": str(scene_path),
        "base_scene": base_keys,
        "fixed": fixed,
        "engine": engine,
        "axes": [{"name": a.name, "key": a.key, "values": list(a.values)} for a in axes],
        "weftsim_version": __version__,
        "command": command_line(),  # the command line that made (or last extended) the sweep
    }


def read_manifest(outdir: Path) -> dict | None:
    path = Path(outdir) / SWEEP_FILE
    if not path.exists():
        return None
    if not path.is_file():  # a directory, a pipe (reading it would wait forever), a device
        raise SweepError(f"{path} is not a file; move it away to start a new sweep there")
    if path.stat().st_size > MAX_MANIFEST_BYTES:
        raise SweepError(f"{path} is {path.stat().st_size / 1e6:.0f} MB, more than any sweep manifest (a million "
                         "cells' values are ~20 MB); move it away to start a new sweep there")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except RecursionError:
        raise SweepError(f"{path} nests too deeply to be a weftsim sweep manifest; move it away to start a new "
                         "sweep there") from None
    except (OSError, ValueError) as exc:
        raise SweepError(f"{path} cannot be read ({exc}); move it away to start a new sweep there") from None
    if not isinstance(data, dict) or data.get("format") != SWEEP_FORMAT:
        raise SweepError(f"{path} is not a weftsim sweep manifest; choose another output directory")
    problem = _manifest_problem(data)
    if problem:
        raise SweepError(f"{path} is damaged ({problem}); move it away (the cell directories can stay) "
                         "and rerun the sweep to rebuild it")
    return data


def _manifest_problem(data: dict) -> str:
    """What is missing or malformed in a manifest of the right format ('' if nothing)."""
    if not isinstance(data.get("engine"), str):
        return "no engine"
    if not isinstance(data.get("base_scene"), dict):
        return "no base scene"
    axes = data.get("axes")
    if not isinstance(axes, list) or not axes:
        return "no varied keys"
    for axis in axes:
        if not isinstance(axis, dict) or not isinstance(axis.get("key"), str) \
                or not isinstance(axis.get("values"), list):
            return f"a varied key is not of the form {{key, values}}: {axis!r:.80}"
    return _axes_problem(axes)


def _axes_problem(axes: list[dict]) -> str:
    """Names, keys and values of the manifest's axes that cannot make a grid ('' if none)."""
    import math

    from weftsim.sweep.grid import resolve_key
    from weftsim.sweep.plan import MAX_GRID_CELLS

    names = []
    for axis in axes:
        name = axis.get("name", axis["key"])
        if not isinstance(name, str) or not name or not SAFE_NAME.match(name):
            return f"axis name {name!r:.40} is not a scene key's name"
        if name in RESERVED_NAMES:
            return f"axis name {name!r} is a column of the table (status, wall_time_s, the peaks ...)"
        try:
            resolve_key(axis["key"])
        except SweepError:
            return f"varied key {axis['key']!r:.60} is not a scene key"
        values = axis["values"]
        if not values or not all(isinstance(v, (str, int, float)) and not (isinstance(v, float) and not math.isfinite(v))
                                 for v in values):
            return f"the values of {name} are not a list of numbers, text or true/false"
        texts = [format_value(v) for v in values]
        if len(set(texts)) != len(texts):
            return f"a value of {name} is listed more than once"
        names.append(name)
    if len(set(names)) != len(names) or len({a["key"] for a in axes}) != len(axes):
        return "an axis is listed more than once"
    cells = math.prod(len(a["values"]) for a in axes)
    if cells > MAX_GRID_CELLS:
        return f"its grid has {cells:,} cells, more than the {MAX_GRID_CELLS:,} a sweep can hold"
    return ""


def _differences(old: dict, new: dict) -> list[str]:
    out = []
    if old["engine"] != new["engine"]:
        out.append(f"engine {old['engine']!r} there, {new['engine']!r} here")
    old_keys = sorted(a["key"] for a in old["axes"])
    new_keys = sorted(a["key"] for a in new["axes"])
    if old_keys != new_keys:
        out.append(f"varied keys {', '.join(old_keys)} there, {', '.join(new_keys)} here")
    changed = sorted(k for k in set(old["base_scene"]) | set(new["base_scene"])
                     if old["base_scene"].get(k) != new["base_scene"].get(k))
    if changed:
        shown = ", ".join(f"{k} = {old['base_scene'].get(k)!r} there, {new['base_scene'].get(k)!r} here"
                          for k in changed[:4])
        more = f" (and {len(changed) - 4} more)" if len(changed) > 4 else ""
        out.append(f"base scene differs: {shown}{more}")
    return out


def merge_manifest(outdir: Path, new: dict) -> dict:
    """Check ``outdir`` can hold this sweep and return the manifest to write (values: union of both grids).

    Raises
    ------
    SweepError
        If ``outdir`` holds a different sweep, or other files but no sweep manifest.
    """
    outdir = Path(outdir)
    old = read_manifest(outdir)
    if old is None:
        if outdir.exists() and any(p.name != LOCK_FILE for p in outdir.iterdir()):
            raise SweepError(f"output directory {outdir} is not empty and holds no {SWEEP_FILE}; "
                             "choose a new or empty directory")
        return new
    problems = _differences(old, new)
    if problems:
        raise SweepError(f"output directory {outdir} holds a different sweep ({'; '.join(problems)}); "
                         "choose another output directory (-o) or remove that one")
    merged = dict(new)
    axes = []
    old_values = {a["key"]: a["values"] for a in old["axes"]}
    for axis in new["axes"]:
        seen = {format_value(v) for v in axis["values"]}
        extra = [v for v in old_values[axis["key"]] if format_value(v) not in seen]
        axes.append({**axis, "values": list(axis["values"]) + extra})
    merged["axes"] = axes
    return merged


def collect_rows(outdir: Path, axis_names: list[str], pending: dict[str, dict] | None = None) -> list[dict]:
    """One row per cell directory holding a ``cell.json``, plus ``pending`` cells (name -> params) not yet run.

    Rows are sorted by the parameters in axis order (numbers numerically).
    """
    outdir = Path(outdir)
    rows = {}
    for child in sorted(p for p in outdir.iterdir() if p.is_dir()) if outdir.exists() else []:
        record = read_record(child)
        if record is None:
            continue
        row = {"cell": child.name, **record.get("params", {}), "status": record.get("status"),
               "wall_time_s": record.get("wall_time_s"), "error": record.get("error", "")}
        metrics = record.get("metrics") or {}
        row.update({c: metrics.get(c) for c in INFO_COLUMNS[2:] + METRIC_COLUMNS})
        rows[child.name] = row
    for name, params in (pending or {}).items():
        rows.setdefault(name, {"cell": name, **params, "status": "pending"})

    def order(row: dict):
        return tuple((0, v, "") if isinstance(v, (int, float)) else (1, 0, str(v))
                     for v in (row.get(n) for n in axis_names))

    return sorted(rows.values(), key=order)


def table_columns(axis_names: list[str]) -> list[str]:
    return ["cell", *axis_names, *INFO_COLUMNS, *METRIC_COLUMNS, "error"]


def table_text(rows: list[dict], axis_names: list[str]) -> str:
    """CSV text: cell, parameters, status, wall time, peaks, percentiles, error (first line)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=table_columns(axis_names), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        out = {}
        for column in writer.fieldnames:
            value = finite_or_none(row.get(column))
            if isinstance(value, float):
                value = f"{value:.10g}"
            elif column == "error" and value:
                value = str(value).splitlines()[0]
            out[column] = "" if value is None else value
        writer.writerow(out)
    return buffer.getvalue()


def read_table(path: Path) -> list[dict[str, str]]:
    """Rows of a written ``sweep.csv`` (strings, as in the file)."""
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


# Columns of sweep.csv that are numbers, the data variables of the labelled grid.
GRID_NUMBERS = ("wall_time_s", "complete_revolutions", "first_contact_deg") + METRIC_COLUMNS


def _coordinate(values: list) -> list:
    """An axis's values in order: numbers ascending (a resumed sweep appends values at the end)."""
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return sorted(values)
    return list(values)


def load_grid(outdir: Path) -> xarray.Dataset:
    """The sweep in ``outdir`` as an :class:`xarray.Dataset` over its varied keys.

    Dimensions are the axes of ``sweep.json`` (by their cell-name names; attribute ``scene_key``
    the dotted key), coordinates their values in file units.  Each number of a cell's record
    (:data:`GRID_NUMBERS`, the columns of ``sweep.csv``) is one float variable, NaN where a cell
    was not run or lacks it; ``status`` is ``"success"``, ``"failed"`` or ``"not run"``.  The
    manifest's engine and base scene name are attributes.  Read from the cells' ``cell.json``
    records, as ``sweep.csv`` is, so a sweep still running or interrupted loads what is finished.

    Raises
    ------
    SweepError
        ``outdir`` holds no sweep or a damaged manifest.
    weftsim.errors.MissingExtra
        xarray is not installed (extra ``weftsim[data]``).
    """
    import numpy as np

    from weftsim.errors import require

    xr = require("xarray", "data", "load_sweep")
    outdir = Path(outdir)
    data = read_manifest(outdir)
    if data is None:
        raise SweepError(f"{outdir}: no {SWEEP_FILE} there, so it is not a sweep directory (weftsim sweep writes one)")
    names = [axis.get("name") or axis["key"] for axis in data["axes"]]
    values = {name: _coordinate(axis["values"]) for name, axis in zip(names, data["axes"])}
    index = {name: {format_value(v): i for i, v in enumerate(values[name])} for name in names}
    shape = tuple(len(values[name]) for name in names)
    numbers = {column: np.full(shape, np.nan) for column in GRID_NUMBERS}
    status = np.full(shape, "not run", dtype=object)
    for row in collect_rows(outdir, names):
        try:
            where = tuple(index[name][format_value(row.get(name))] for name in names)
        except KeyError:  # a cell directory of values the manifest does not list: not part of the grid
            continue
        status[where] = row.get("status") or "not run"
        for column in GRID_NUMBERS:
            value = finite_or_none(row.get(column))
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                numbers[column][where] = float(value)
    variables = {column: (names, array) for column, array in numbers.items()}
    variables["status"] = (names, status.astype(str))
    grid = xr.Dataset(variables, coords={name: values[name] for name in names})
    for name, axis in zip(names, data["axes"]):
        grid[name].attrs["scene_key"] = axis["key"]
    grid.attrs.update({"engine": data["engine"], "scene": str(data["base_scene"].get("name", "")),
                       "scene_path": str(data.get("scene_path", "")), "sweep_directory": str(outdir)})
    return grid
