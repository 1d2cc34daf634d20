"""One sweep cell: solved in a worker from plain data, stored by the sweep's client.

:func:`solve_cell` is the function sent to the local process pool or to a Dask
cluster: top level, picklable, plain-data arguments.  It receives the cell's
*resolved scene as data* (its dotted file keys in file units, as in ``summary.json``),
never a path, so a worker needs neither the scene file nor the sweep directory: it
renders the run's files in a private temporary directory and returns their bytes.
The client then stores them with :func:`store_cell`: the run's files, then (on
failure) ``error.txt``, and LAST, atomically, the cell manifest ``cell.json``.  A
cell counts as finished only when ``cell.json`` says success for the same scene and
engine and ``summary.json`` is complete and holds that same scene, so a process
killed at any moment leaves either a finished cell or one that the next run redoes,
and a run written over a cell by hand (``weftsim run -o SWEEP/cell``) is redone too.
"""

from __future__ import annotations

import json
import math
import os
import socket
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any
from typing import TYPE_CHECKING

from weftsim.post.record import written_by
from weftsim.version import __version__

if TYPE_CHECKING:
    from weftsim.post.results import RunResult

CELL_FILE = "cell.json"
ERROR_FILE = "error.txt"
SUMMARY_FILE = "summary.json"
CELL_FORMAT = "weftsim-sweep-cell/1"
MAX_RECORD_BYTES = 16 * 2**20  # a cell.json is a few kB (its scene's keys, its metrics)

# Channels summarised per cell: contact_force_N is joint E's, contact_force_f_N joint F's.  A joint that is
# ideal in a cell has no contact force: its columns are empty there (not 0, which would read as a force
# the joint never carried; the ideal joint's reaction is not a contact force).
METRIC_CHANNELS = ("driving_torque_Nm", "rapier_acceleration_m_s2", "contact_force_N", "contact_force_f_N")
JOINT_OF_CHANNEL = {"contact_force_N": "joint", "contact_force_f_N": "joint_f"}


def normalise(data: Any) -> Any:
    """The value as it reads back from JSON (tuples -> lists, NaN -> None), for comparing manifests."""
    from weftsim.post.output import to_json

    return json.loads(to_json({"v": data}))["v"]


def _peak(window: dict[str, dict[str, float]], channel: str) -> float:
    """Largest magnitude of a channel over a window: max(|min|, |max|)."""
    return max(abs(window[channel]["min"]), abs(window[channel]["max"]))


def cell_metrics(result: RunResult) -> dict[str, Any]:
    """Peaks and percentiles of one run for the sweep table.

    ``*_rev1_peak`` is the largest magnitude over the first crank revolution (or the
    part of it that was run), ``*_last_peak`` over the last complete revolution
    (``last_revolution``, 1-based; the first one when the run is shorter than one),
    ``*_p99`` the time-weighted 99th percentile of the magnitude over revolutions
    2..N (None with fewer than two complete revolutions).  Peaks come from the
    solver steps, which resolve the impacts (see :mod:`weftsim.post.analysis`).  The
    contact force of a joint that is ideal in the run (E's ``contact_force_N``,
    F's ``contact_force_f_N``) is None: there is no contact there.
    """
    from weftsim.post.analysis import complete_revolutions, peaks, statistics

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
        joint = JOINT_OF_CHANNEL.get(channel)
        if channel not in first or (joint is not None and getattr(result.scene, joint).is_ideal):
            continue  # an ideal joint: no contact force (the columns stay empty)
        out[f"{channel}_rev1_peak"] = _peak(first, channel)
        out[f"{channel}_last_peak"] = _peak(last, channel)
        out[f"{channel}_p99"] = stats[channel]["p99_abs"] if stats else None
    return out


def cell_record(name: str, params: dict, overrides: dict, scene_keys: dict | None, engine: str, status: str,
                error: str, wall_time_s: float, metrics: dict | None, worker: dict | None = None) -> dict[str, Any]:
    """The content of ``cell.json``; ``worker`` says where the cell ran (:func:`worker_info`)."""
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
        "worker": worker,
        "weftsim_version": __version__,
    }


def write_cell_record(cell_dir: Path, record: dict, detail: str = "") -> None:
    """Write ``error.txt`` (failed cells) and then, last, ``cell.json``; both atomic."""
    from weftsim.post.output import write_json, write_text

    if record["status"] != "success":
        write_text(cell_dir / ERROR_FILE, record["error"] + ("\n\n" + detail if detail else "") + "\n")
    write_json(cell_dir / CELL_FILE, record)


SCRATCH_IN_MEMORY = "/dev/shm"
_CELLS_IN_THIS_PROCESS = 0  # cells this worker process has solved (it runs many; see worker_info)


def worker_info() -> dict[str, Any]:
    """Where a cell ran: host, process id, and how many cells that process had solved (1 = its first)."""
    return {"host": socket.gethostname(), "pid": os.getpid(), "cell_number": _CELLS_IN_THIS_PROCESS}


def _scratch_places() -> list[str | None]:
    """Where to render a run: a memory file system first (Linux ``/dev/shm``), then the system's temp dir."""
    places: list[str | None] = [None]
    if os.path.isdir(SCRATCH_IN_MEMORY) and os.access(SCRATCH_IN_MEMORY, os.W_OK | os.X_OK):
        places.insert(0, SCRATCH_IN_MEMORY)
    return places


def render_run(result: RunResult, figure: bool) -> dict[str, bytes]:
    """The files :func:`weftsim.post.output.write_run` writes for ``result``, as bytes (name -> content).

    They are written to a private temporary directory of this process and read back; a memory
    file system halves the cost of that detour (1 revolution: 13 ms against 24-32 ms on this
    machine's disk, next to a 29 ms solve), and a full one falls back to the disk.
    """
    from weftsim.post.output import write_run

    error: OSError | None = None
    for place in _scratch_places():
        try:
            with tempfile.TemporaryDirectory(prefix="weftsim-cell-", dir=place) as private:
                write_run(result, private, figure=figure, force=True)
                return {p.name: p.read_bytes() for p in sorted(Path(private).iterdir()) if p.is_file()}
        except OSError as exc:  # e.g. the memory file system is full: try the next place
            error = exc
    raise error if error is not None else OSError("no scratch directory to write the cell's files in")


def solve_cell(name: str, scene_keys: dict, engine: str, figure: bool = False, command: str | None = None
               ) -> dict[str, Any]:
    """Solve one cell in a worker and return its outcome with the bytes of its run files.

    Parameters
    ----------
    name : str
        The cell's name (for messages).
    scene_keys : dict
        The cell's resolved scene as dotted file keys in file units (absent optional keys left out);
        :func:`weftsim.input.scene.scene_from_keys` rebuilds it without any file.
    engine : str
        ``reference``, ``exudyn`` or ``module:function`` (checked by the sweep before it starts).
    figure : bool
        Also render the run's ``channels.png``.
    command : str, optional
        The command line that started the sweep, recorded in the cell's manifest and ``scene.toml``
        (a worker's own arguments say nothing); None records the worker's.

    Returns
    -------
    dict
        ``status`` (``success`` or ``failed``), ``error``, ``detail`` (traceback of an exception),
        ``wall_time_s``, ``metrics``, ``files`` (file name -> bytes, written by the client) and
        ``worker`` (:func:`worker_info`).  Exceptions of the scene or engine are caught and returned;
        only interrupts pass.  Nothing is read from or written to the sweep directory.
    """
    global _CELLS_IN_THIS_PROCESS
    from weftsim.input.scene import scene_from_keys
    from weftsim.sweep.engines import engine_solve

    _CELLS_IN_THIS_PROCESS += 1
    start = time.perf_counter()
    files, metrics, detail = {}, None, ""
    try:
        scene = scene_from_keys(scene_keys, f"sweep cell {name}")
        result = engine_solve(engine)(scene, progress=None)
        if command is None:
            files = render_run(result, figure)
        else:
            with written_by(command):
                files = render_run(result, figure)
        metrics = cell_metrics(result)
        status, error = result.status, result.message
        if status != "success" and not error:
            error = "the engine reported failure without a message"
    except Exception as exc:  # a cell's failure is data, not a reason to stop the sweep
        status, error, detail = "failed", f"{type(exc).__name__}: {exc}", traceback.format_exc()
    return {"status": status, "error": error, "detail": detail, "wall_time_s": time.perf_counter() - start,
            "metrics": metrics, "files": files, "worker": worker_info()}


def _listed_files(cell_dir: Path) -> set[str]:
    """Plain file names the cell's previous run manifest lists (anything else in it is ignored)."""
    from weftsim.post.output import MANIFEST

    if not (cell_dir / MANIFEST).is_file():
        return set()
    try:
        listed = json.loads((cell_dir / MANIFEST).read_text(encoding="utf-8")).get("files", [])
    except (OSError, ValueError, AttributeError, RecursionError):
        return set()
    return {n for n in listed if isinstance(n, str) and n and "/" not in n and n not in (".", "..")} \
        if isinstance(listed, list) else set()


def store_cell(cell_dir: Path, record: dict, files: dict[str, bytes], detail: str = "") -> None:
    """Write a cell's run files, then ``error.txt`` (failed cells) and last ``cell.json``; each atomic.

    Files the cell's previous run listed and this one did not write are removed if they are
    plain files; a listed name that is a directory (or a link) is left alone: a cell's own
    files are never directories, so that one is not ours to remove.
    """
    from weftsim.post.output import MANIFEST, prepare_directory, write_atomic

    # force: a cell directory belongs to its sweep (checked by the driver) and may hold a killed run's files.
    cell_dir = prepare_directory(cell_dir, force=True)
    for stale in (CELL_FILE, ERROR_FILE):
        (cell_dir / stale).unlink(missing_ok=True)
    old = _listed_files(cell_dir)
    for file_name in sorted(files, key=lambda n: n == MANIFEST):  # the run's manifest after its files
        def write(tmp: Path, data: bytes = files[file_name]) -> None:
            tmp.write_bytes(data)

        write_atomic(cell_dir / file_name, write)
    for stale in old - set(files):
        path = cell_dir / stale
        if path.is_file() and not path.is_symlink():
            path.unlink(missing_ok=True)
    write_cell_record(cell_dir, record, detail)


def read_record(cell_dir: Path) -> dict | None:
    """The cell's ``cell.json``, or None if absent, unreadable or malformed (a cell to run again).

    Malformed (:func:`record_problem`): a record damaged or edited by hand is not trusted for the
    table or the grid; the next run of the sweep runs its cell again.
    """
    path = Path(cell_dir) / CELL_FILE
    try:
        if not path.is_file() or path.stat().st_size > MAX_RECORD_BYTES:  # a pipe, a device, or too big to be ours
            return None
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(record, dict) or record.get("format") != CELL_FORMAT or record_problem(record, Path(cell_dir)):
        return None
    return record


def _scalar(value: Any) -> bool:
    return isinstance(value, (str, int, float)) and not (isinstance(value, float) and not math.isfinite(value))


def record_problem(record: dict, cell_dir: Path) -> str:
    """What makes ``record`` (a parsed ``cell.json``) unusable ('' if nothing): a field of the wrong
    type, a status other than success or failed, or parameters that do not name its directory."""
    from weftsim.sweep.grid import cell_name

    params = record.get("params")
    if not isinstance(params, dict) or not params or not all(isinstance(k, str) and _scalar(v)
                                                             for k, v in params.items()):
        return "params is not a map of parameter names to values"
    if cell_name(params) != cell_dir.name:
        return f"params name the cell {cell_name(params)!r}, not its directory {cell_dir.name!r}"
    if record.get("status") not in ("success", "failed"):
        return "status is neither success nor failed"
    for key, kind in (("metrics", dict), ("error", str), ("engine", str)):
        if not isinstance(record.get(key), kind):
            return f"{key} is not a {kind.__name__}"
    if not all(v is None or isinstance(v, (int, float)) and not isinstance(v, bool)
               for v in record["metrics"].values()):
        return "a metric is not a number"
    wall = record.get("wall_time_s")
    if wall is not None and (isinstance(wall, bool) or not isinstance(wall, (int, float))):
        return "wall_time_s is not a number"
    if record.get("scene") is not None and not isinstance(record["scene"], dict):
        return "scene is not a map of scene keys"
    return ""


def is_finished(cell_dir: Path, scene_keys: dict, engine: str) -> bool:
    """True if the cell holds a successful run of exactly this scene and engine: in ``cell.json`` and in
    the run's own ``summary.json``."""
    record = read_record(cell_dir)
    if record is None or record.get("status") != "success" or record.get("engine") != engine:
        return False
    expected = normalise(scene_keys)
    if record.get("scene") != expected:
        return False
    if not (Path(cell_dir) / SUMMARY_FILE).is_file():  # also a pipe, whose reading would wait forever
        return False
    try:
        summary = json.loads((Path(cell_dir) / SUMMARY_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return False
    # The run on disk must be the cell's own: `weftsim run -o SWEEP/cell` with another scene replaces
    # summary.json and channels.csv but not cell.json, and must not pass for this cell.
    return isinstance(summary, dict) and summary.get("status") == "success" \
        and normalise(summary.get("scene")) == expected


def finite_or_none(value: Any) -> Any:
    """Floats that are NaN or infinite become None (empty in the CSV table)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
