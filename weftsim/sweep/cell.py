"""One sweep cell: run a scene variant in a worker and record it loss-free.

:func:`run_cell` is the function sent to the local process pool or to a Dask
cluster: top level, picklable, plain-data arguments, small dict back.  It writes
the run with :func:`weftsim.output.write_run`, then (on failure) ``error.txt``,
and LAST, atomically, the cell manifest ``cell.json``.  A cell counts as finished
only when ``cell.json`` says success for the same scene and engine and
``summary.json`` is complete, so a process killed at any moment leaves either a
finished cell or one that the next run redoes.
"""

from __future__ import annotations

import importlib
import json
import math
import time
import traceback
from pathlib import Path
from typing import Any, Callable

from weftsim import __version__

CELL_FILE = "cell.json"
ERROR_FILE = "error.txt"
SUMMARY_FILE = "summary.json"
CELL_FORMAT = "weftsim-sweep-cell/1"

# Engine names -> "module:function" of solve(scene, progress=None) -> RunResult.
ENGINES = {"reference": "weftsim.reference:solve", "exudyn": "weftsim.exudyn_engine:solve"}

# Channels whose peaks and 99th percentiles the sweep table reports (issue 8).
METRIC_CHANNELS = ("driving_torque_Nm", "rapier_acceleration_m_s2", "contact_force_N")


def resolve_engine(engine: str) -> Callable:
    """``solve`` of an engine name, or of ``package.module:function`` (a plug-in or test engine)."""
    target = ENGINES.get(engine, engine)
    module, sep, function = target.partition(":")
    if not sep or not module or not function:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)} or 'module:function', got {engine!r}")
    return getattr(importlib.import_module(module), function)


def normalise(data: Any) -> Any:
    """The value as it reads back from JSON (tuples -> lists, NaN -> None), for comparing manifests."""
    from weftsim.output import to_json

    return json.loads(to_json({"v": data}))["v"]


def _peak(window: dict[str, dict[str, float]], channel: str) -> float:
    """Largest magnitude of a channel over a window: max(|min|, |max|)."""
    return max(abs(window[channel]["min"]), abs(window[channel]["max"]))


def cell_metrics(result) -> dict[str, Any]:
    """Peaks and percentiles of one run for the sweep table.

    ``*_rev1_peak`` is the largest magnitude over the first crank revolution (or the
    part of it that was run), ``*_last_peak`` over the last complete revolution
    (``last_revolution``, 1-based; the first one when the run is shorter than one),
    ``*_p99`` the time-weighted 99th percentile of the magnitude over revolutions
    2..N (None with fewer than two complete revolutions).  Peaks come from the
    solver steps, which resolve the impacts (see :mod:`weftsim.analysis`).
    """
    from weftsim.analysis import complete_revolutions, peaks, statistics

    n = complete_revolutions(result)
    out: dict[str, Any] = {
        "complete_revolutions": n,
        "last_revolution": None,
        "first_contact_deg": result.first_contact_angle_deg,
        "solver_wall_time_s": result.wall_time_s,
    }
    for channel in METRIC_CHANNELS:
        out.update({f"{channel}_rev1_peak": None, f"{channel}_last_peak": None, f"{channel}_p99": None})
    if result.steps["time_s"].size == 0:
        return out
    first = peaks(result, 0)
    last_index = max(n - 1, 0)
    last = peaks(result, last_index)
    out["last_revolution"] = last_index + 1
    stats = statistics(result) if n >= 2 else None
    for channel in METRIC_CHANNELS:
        out[f"{channel}_rev1_peak"] = _peak(first, channel)
        out[f"{channel}_last_peak"] = _peak(last, channel)
        out[f"{channel}_p99"] = stats[channel]["p99_abs"] if stats else None
    return out


def cell_record(name: str, params: dict, overrides: dict, scene_keys: dict | None, engine: str, status: str,
                error: str, wall_time_s: float, metrics: dict | None) -> dict[str, Any]:
    """The content of ``cell.json`` (also the dict :func:`run_cell` returns)."""
    return {
        "format": CELL_FORMAT,
        "cell": name,
        "params": params,
        "overrides": overrides,
        "engine": engine,
        "status": status,
        "error": error,
        "wall_time_s": wall_time_s,
        "metrics": metrics or {},
        "scene": scene_keys,
        "weftsim_version": __version__,
    }


def write_cell_record(cell_dir: Path, record: dict, detail: str = "") -> None:
    """Write ``error.txt`` (failed cells) and then, last, ``cell.json``; both atomic."""
    from weftsim.output import write_json, write_text

    if record["status"] != "success":
        write_text(cell_dir / ERROR_FILE, record["error"] + ("\n\n" + detail if detail else "") + "\n")
    write_json(cell_dir / CELL_FILE, record)


def run_cell(scene_path: str, overrides: dict, params: dict, cell_dir: str, engine: str,
             figure: bool = False) -> dict[str, Any]:
    """Run one cell: load the scene with ``overrides``, solve, write the run, record the outcome.

    Parameters
    ----------
    scene_path : str
        Base scene file (must be readable where this runs: a shared file system on a cluster).
    overrides : dict
        Dotted scene keys -> values in file units (the cell's parameters and the sweep's fixed keys).
    params : dict
        The cell's parameters by short name (for the table).
    cell_dir : str
        The cell's result directory.
    engine : str
        ``reference``, ``exudyn`` or ``module:function``.
    figure : bool
        Also write the run's ``channels.png``.

    Returns
    -------
    dict
        The cell record (see :func:`cell_record`); ``status`` is ``success`` or ``failed``.
        Exceptions of the scene or engine are caught and recorded; only interrupts pass.
    """
    from weftsim.output import prepare_directory
    from weftsim.scene import load_scene, to_file_keys

    start = time.perf_counter()
    # force: a cell directory belongs to its sweep (checked by the driver) and may hold a killed run's files.
    directory = prepare_directory(cell_dir, force=True)
    for stale in (CELL_FILE, ERROR_FILE):
        (directory / stale).unlink(missing_ok=True)
    scene_keys, metrics, detail = None, None, ""
    try:
        scene = load_scene(scene_path, overrides)
        scene_keys = normalise(to_file_keys(scene))
        result = resolve_engine(engine)(scene, progress=None)
        from weftsim.output import write_run

        write_run(result, directory, figure=figure, force=True)
        metrics = cell_metrics(result)
        status, error = result.status, result.message
        if status != "success" and not error:
            error = "the engine reported failure without a message"
    except Exception as exc:  # a cell's failure is data, not a reason to stop the sweep
        status, error, detail = "failed", f"{type(exc).__name__}: {exc}", traceback.format_exc()
    wall = time.perf_counter() - start
    record = cell_record(directory.name, params, overrides, scene_keys, engine, status, error, wall, metrics)
    write_cell_record(directory, record, detail)
    return record


def read_record(cell_dir: Path) -> dict | None:
    """The cell's ``cell.json``, or None if absent or unreadable (a cell to run again)."""
    try:
        record = json.loads((Path(cell_dir) / CELL_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) and record.get("format") == CELL_FORMAT else None


def is_finished(cell_dir: Path, scene_keys: dict, engine: str) -> bool:
    """True if the cell holds a successful run of exactly this scene and engine, with a complete summary."""
    record = read_record(cell_dir)
    if record is None or record.get("status") != "success" or record.get("engine") != engine:
        return False
    if record.get("scene") != normalise(scene_keys):
        return False
    try:
        summary = json.loads((Path(cell_dir) / SUMMARY_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return summary.get("status") == "success"


def finite_or_none(value: Any) -> Any:
    """Floats that are NaN or infinite become None (empty in the CSV table)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
