"""Writing results to disk: atomic CSV, JSON and figure files.

Every file is written to a temporary name in the target directory and then
renamed over the final name, so a run that dies leaves either the complete
previous file or the complete new one, never half of one.  Files get the mode
the user's umask gives a new file (as ``open`` would), not the 0600 of a temporary file.

A write that fails (a full disk, a quota) does not lose the computed result: the
other files are still written, the ones that failed are kept in a rescue directory
under the system's temporary directory where it can be written, the directory's
manifest says ``"state": "incomplete"`` and which files are missing, and
:class:`WriteFailed` says where everything is.  The manifest is written with room
to spare when the directory is opened, so its last update fits on a full disk.
The size of a run's output is estimated from the scene before anything is created
(:func:`check_output_fits`).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import OutputError, WriteFailed
from weftsim.post.npz_guard import available_memory
from weftsim.post.record import MANIFEST, SCENE_FILE, check_same_kind, check_same_scene, provenance, scene_toml
from weftsim.post.results import RunResult

if TYPE_CHECKING:
    from collections.abc import Mapping

    from matplotlib.figure import Figure
    from numpy.typing import ArrayLike

    from weftsim.input.params import Scene


# Bytes the manifest reserves on disk when a directory is opened (JSON allows trailing blanks):
# its final state (a few hundred bytes for the files of a run, more than its opening state) is then
# written over blocks the file already holds, which needs no free space.  A manifest recording a
# resolved scene (~5 kB) reserves whole multiples of it with at least MANIFEST_ROOM to spare.
MANIFEST_RESERVE = 4096
MANIFEST_ROOM = 2048
# Characters per value in channels.csv: "%.10g" gives at most 17 ("-1.234567891e-100") and a comma.
CSV_BYTES_PER_VALUE = 18
# Bytes of memory per output value while a run is held: 8 for the sample, and at least as many for
# the solver steps (Exudyn takes one or more steps per output sample) and the array building the CSV.
MEMORY_BYTES_PER_VALUE = 24


def prepare_directory(path: str | Path, force: bool = False, scene: Scene | None = None,
                      kind: str | None = None, create: bool = True) -> Path:
    """Create ``path`` (and parents) and check it is a writable directory of ours.

    A directory that already holds files but no weftsim manifest was not written by
    weftsim: it is refused (unless ``force``) so a run never mixes its files with others.
    With ``scene``, a directory holding the results of another resolved scene is refused too
    (unless ``force``; :func:`weftsim.post.record.check_same_scene`), before anything is written.
    With ``kind`` (the manifest's ``"kind"`` the caller writes: ``"run"``, ``"wear"``, ``"wear ensemble"``,
    ...), a directory holding another command's results is refused too (:func:`~weftsim.post.record.check_same_kind`).
    With ``create = False`` every check is made and nothing is created (a directory that does not exist yet must
    be creatable): the command line checks its output before the checks that may still refuse the run (the
    engines' estimates), so a refused run leaves no empty directory behind, and creates it once they passed.
    """
    path = Path(path)
    if path.is_dir() and not force and not (path / MANIFEST).exists() and any(path.iterdir()):
        raise OutputError(
            f"output directory {path} is not empty and was not written by weftsim; "
            "choose another directory with -o, or pass --force to write into it anyway"
        )
    if scene is not None:  # first: results of another scene are named by the keys that differ
        check_same_scene(path, scene, force)
    if kind is not None:
        check_same_kind(path, kind, force)
    if create:
        try:
            path.mkdir(parents=True, exist_ok=True)
        except FileExistsError:
            raise OutputError(f"output directory {path} exists and is not a directory") from None
        except OSError as exc:
            raise OutputError(f"cannot create output directory {path}: {exc.strerror}") from None
    elif not (path.exists() or path.is_symlink()):
        _nearest_ancestor(path, f"cannot create output directory {path}")
        return path
    elif not path.is_dir():
        raise OutputError(f"output directory {path} exists and is not a directory")
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"output directory {path} is not writable")
    manifest = path / MANIFEST
    if (manifest.exists() or manifest.is_symlink()) and (manifest.is_symlink() or not manifest.is_file()):
        raise OutputError(f"{manifest} is not weftsim's manifest file (a directory, a link or a device); "
                          "remove it, or choose another directory with -o")
    return path


def _nearest_ancestor(path: Path, what: str) -> Path | None:
    """The nearest existing ancestor of ``path``, which must be a writable directory: an OutputError starting with
    ``what`` (the thing that cannot be made) names the part of the path in the way; None if no ancestor exists."""
    for ancestor in path.parents:
        if ancestor.exists() or ancestor.is_symlink():
            if not ancestor.is_dir():
                raise OutputError(f"{what}: {ancestor} is a file, not a directory")
            if not os.access(ancestor, os.W_OK | os.X_OK):
                raise OutputError(f"{what}: directory {ancestor} is not writable")
            return ancestor
    return None


def check_file_target(target: str | Path) -> Path:
    """Check, creating nothing, that the file ``target`` can be written once a long computation is done.

    Its directory must exist and be writable, or be creatable: the nearest existing ancestor a
    writable directory.  Raises :class:`OutputError` naming the part of the path that is in the way.
    """
    target = Path(target)
    if target.is_dir():
        raise OutputError(f"cannot write {target}: it is a directory; give a file name")
    ancestor = _nearest_ancestor(target, f"cannot write {target}")
    if ancestor == target.parent:  # permissions do not tell all (a read-only mount, /proc): try a file
        try:
            fd, probe = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=ancestor)
            os.close(fd)
            os.unlink(probe)
        except OSError as exc:
            raise OutputError(f"cannot write {target}: {exc.strerror or exc}") from None
    return target


def _umask() -> int:
    mask = os.umask(0o022)  # the only way to read it is to set it; put it back at once
    os.umask(mask)
    return mask


def write_atomic(target: Path, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp_path)`` and rename the temporary file onto ``target``.

    The file gets mode 0666 less the umask, as a file opened for writing would.
    """
    target = Path(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
    finally:
        os.close(fd)
    try:
        write(Path(tmp))
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


def write_text(target: Path, text: str) -> Path:
    return write_atomic(target, lambda p: p.write_text(text, encoding="utf-8"))


def _json_default(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def _clean(value):
    """NaN and inf are not JSON: write them as null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def to_json(data: dict) -> str:
    return json.dumps(_clean(data), indent=2, default=_json_default) + "\n"


def write_json(target: Path, data: dict) -> Path:
    return write_text(target, to_json(data))


def write_csv(target: Path, columns: Mapping[str, ArrayLike]) -> Path:
    """Columns of equal length, header = column names, full double precision."""
    names = list(columns)
    table = np.column_stack([np.asarray(columns[n], dtype=float) for n in names]) if names else np.zeros((0, 0))

    def write(tmp: Path) -> None:
        np.savetxt(tmp, table, delimiter=",", header=",".join(names), comments="", fmt="%.10g")

    return write_atomic(target, write)


# zlib level of a PNG figure: the same pixels as matplotlib's default 6 in 60 % of the encoding's CPU time (0.08
# against 0.13 s for the loom run's channels.png and orbit.png), the files 2-12 % larger.
PNG_COMPRESS_LEVEL = 3


def write_figure(target: Path, figure: Figure) -> Path:
    import sys

    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    kind = target.suffix.lstrip(".")
    options: dict[str, Any] = {"pil_kwargs": {"compress_level": PNG_COMPRESS_LEVEL}} if kind == "png" else {}
    if isinstance(figure.get_layout_engine(), PlaceHolderLayoutEngine):
        # Figure.tight_layout() places the axes once and leaves this placeholder behind, for which savefig draws
        # the whole figure a second time (without pixels) before drawing it: the positions are final, so drop it
        # (the loom run's two figures: 0.23 of 0.65 s of drawing on a slow machine, the same pixels).
        figure.set_layout_engine(None)
    try:
        return write_atomic(target, lambda p: figure.savefig(p, format=kind, dpi=130, **options))
    finally:
        if "matplotlib.pyplot" in sys.modules:  # a pyplot figure: free it (weftsim.post.plots.figure() are not held)
            sys.modules["matplotlib.pyplot"].close(figure)


def _manifest_files(outdir: Path) -> set[str]:
    """Plain file names the directory's manifest lists (none if it is unreadable or malformed)."""
    if not (outdir / MANIFEST).is_file():  # also a pipe, whose reading would wait forever
        return set()
    try:
        listed = json.loads((outdir / MANIFEST).read_text()).get("files", [])
    except (OSError, ValueError, RecursionError, AttributeError):
        return set()
    if not isinstance(listed, list):
        return set()
    return {n for n in listed if isinstance(n, str) and n not in ("", ".", "..") and "/" not in n and "\0" not in n}


def _overwrite_in_place(target: Path, text: str) -> None:
    """Write ``text`` over the blocks ``target`` already holds (padded with blanks to its size)."""
    data = text.encode("utf-8")
    with target.open("r+b") as file:
        size = file.seek(0, os.SEEK_END)
        if len(data) > size:
            raise OSError(f"{target.name} has no room reserved for {len(data)} bytes")
        file.seek(0)
        file.write(data + b" " * (size - len(data)))


def _set_manifest(outdir: Path, data: dict, reserve: bool = False) -> None:
    """Write the manifest atomically; on a full disk over its reserved room instead."""
    text = to_json(data)
    room = MANIFEST_RESERVE * math.ceil((len(text) + MANIFEST_ROOM) / MANIFEST_RESERVE)
    try:
        write_text(outdir / MANIFEST, text.ljust(room) if reserve else text)
    except OSError:
        if reserve or not (outdir / MANIFEST).exists():
            raise
        _overwrite_in_place(outdir / MANIFEST, text)


def begin_directory(outdir: Path, what: dict) -> None:
    """Mark the directory as being written: a run killed between two files leaves this mark.

    Each file is atomic on its own; this manifest (``"state": "writing"``) tells a reader that
    the directory may hold a mix of the previous run's and this run's complete files.  It is
    padded to :data:`MANIFEST_RESERVE` bytes, so its final state fits even on a full disk.
    """
    _set_manifest(outdir, {**what, "state": "writing", "files": sorted(_manifest_files(outdir))}, reserve=True)
    for leftover in outdir.glob(".*.part"):  # temporary files of a run that was killed while writing
        leftover.unlink(missing_ok=True)


def finish_directory(outdir: Path, written: dict[str, Path], what: dict) -> None:
    """Write the manifest last (``"state": "complete"``), then delete files an earlier run left.

    Afterwards the directory holds exactly this run's files (plus anything weftsim did not write).
    """
    old = _manifest_files(outdir)
    names = sorted(p.name for p in written.values())
    _set_manifest(outdir, {**what, "state": "complete", "files": names})
    for stale in old - set(names):
        path = outdir / stale
        if stale != MANIFEST and (path.is_symlink() or path.is_file()):  # never a directory someone put there
            path.unlink(missing_ok=True)


def _rescue(failed: dict[str, tuple[str, Callable[[Path], Path]]]) -> tuple[Path | None, dict[str, str]]:
    """Write the files that failed into a new directory under the system's temporary directory."""
    try:
        rescue = Path(tempfile.mkdtemp(prefix="weftsim-rescue-"))
    except OSError as exc:
        return None, {name: exc.strerror or str(exc) for name, _ in failed.values()}
    errors = {}
    for name, write in failed.values():
        try:
            write(rescue / name)
        except OSError as exc:
            errors[name] = exc.strerror or str(exc)
    if len(errors) == len(failed):
        shutil.rmtree(rescue, ignore_errors=True)
        return None, errors
    return rescue, errors


def write_files(outdir: Path, what: dict, files: dict[str, tuple[str, Callable[[Path], Path]]],
                scene: Scene | None = None, on_write: Callable[[Path], None] | None = None) -> dict[str, Path]:
    """Write a set of files into ``outdir`` under its manifest; keep what fails elsewhere.

    Parameters
    ----------
    outdir : Path
        A directory checked by :func:`prepare_directory`.
    what : dict
        What the files are (kind, scene, ...), copied into the manifest.
    files : dict
        kind -> (file name, ``write(target) -> Path``), written in this order; after a failure
        the later ones are still attempted (a small summary may fit where a large CSV did not).
    scene : Scene, optional
        The scene of these results: the manifest records it resolved and the command line
        (:func:`weftsim.post.record.provenance`), and ``scene.toml`` holds it as a scene file.
    on_write : callable, optional
        Called with each file's path before it is written (progress on a long write).

    Returns
    -------
    dict
        kind -> written path.

    Raises
    ------
    WriteFailed
        A file could not be written.  Every other file was still attempted, the failed ones
        went to a rescue directory where possible, and the manifest says ``"incomplete"``.
    """
    if scene is not None:
        what = {**what, **provenance(scene)}
        files = {**files, "scene": (SCENE_FILE, lambda target: write_text(target, scene_toml(scene)))}
    begin_directory(outdir, what)
    written, failed, reasons = {}, {}, {}
    for kind, (name, write) in files.items():
        if on_write is not None:
            on_write(outdir / name)
        try:
            written[kind] = write(outdir / name)
        except OSError as exc:
            failed[kind] = (name, write)
            reasons[name] = exc.strerror or str(exc)
    if not failed:
        finish_directory(outdir, written, what)
        return written
    rescue, lost = _rescue(failed)
    missing = sorted(reasons)
    state = {**what, "state": "incomplete", "files": sorted(p.name for p in written.values()),
             "missing": {name: reasons[name] for name in missing},
             "rescued_to": str(rescue) if rescue else None}  # fmt: skip
    try:
        _set_manifest(outdir, state)
        marked = " (manifest state 'incomplete')"
    except OSError:
        marked = " (the manifest could not be updated: it still says 'writing')"
    kept = [name for name in missing if name not in lost]
    text = f"cannot write {', '.join(missing)} to {outdir}: {reasons[missing[0]]}"
    if written:
        text += f"; {', '.join(sorted(p.name for p in written.values()))} written there"
    text += marked
    if kept:
        text += f"; {', '.join(kept)} kept in {rescue}"
    if lost:
        text += f"; {', '.join(sorted(lost))} could not be kept anywhere ({lost[sorted(lost)[0]]}): free space and rerun"
    raise WriteFailed(text)


def _free_disk(path: Path) -> int | None:
    """Free bytes on the file system that would hold ``path`` (its nearest existing ancestor), or
    None where that says nothing (a pseudo file system such as /proc reports a size of 0)."""
    path = Path(os.path.abspath(path))
    for candidate in (path, *path.parents):
        if candidate.exists():
            try:
                usage = shutil.disk_usage(candidate)
            except OSError:
                return None
            return usage.free if usage.total > 0 else None
    return None


def _size(n: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.3g} {unit}"
        n /= 1000
    raise AssertionError("unreachable")


def check_output_fits(rows: float, columns: int, outdir: Path, what: str, runs: int = 1,
                      fix: str = "a coarser output.sample_deg (any value up to 0.5 deg) or fewer drive.revolutions") -> None:
    """Refuse, before anything is created, an output grid that cannot be held or written.

    ``runs`` results of ``rows`` x ``columns`` values are held in memory
    (:data:`MEMORY_BYTES_PER_VALUE` each) and written as CSV (:data:`CSV_BYTES_PER_VALUE`).
    Raises :class:`OutputError` when the memory available or the free disk space under
    ``outdir`` is smaller: ``what`` names the scene keys that set the size, ``fix`` what to change.
    """
    values = float(rows) * columns * runs
    memory, disk = values * MEMORY_BYTES_PER_VALUE, values * CSV_BYTES_PER_VALUE
    available, free = available_memory(), _free_disk(outdir)
    short = []
    if available is not None and memory > available:
        short.append(f"~{_size(memory)} of memory (available: {_size(available)})")
    if free is not None and disk > free:
        short.append(f"~{_size(disk)} of CSV (free under {outdir}: {_size(free)})")
    if short:
        raise OutputError(f"{what} gives {rows:.3g} output samples, {' and '.join(short)}: use {fix}")


def output_rows(scene: Scene) -> float:
    """Samples of a run's output grid: one per ``output.sample_deg`` of crank over the run, and the end."""
    return math.floor(scene.drive.end_time * scene.drive.speed / scene.output.sample_angle) + 2


def write_run(result: RunResult, outdir: str | Path, figure: bool = True, force: bool = False,
              npz: bool = False, on_write: Callable[[Path], None] | None = None) -> dict[str, Path]:
    """Write ``channels.csv``, ``summary.json``, ``channels.png``, (clearance joint) ``orbit.png`` and (an
    ``[exchange]``) ``exchange.png`` for one run, atomically each.

    With ``npz`` also ``result.npz``: the whole result, per-step data included, losslessly
    (:func:`weftsim.post.results.save_npz`; ``weftsim.load_result`` reads it).  ``weftsim run`` asks for
    it; a sweep's cells do not (a 10-revolution result is a few MB, times every cell).

    Raises :class:`WriteFailed` (after writing what it can) when a file cannot be written.
    """
    from weftsim.post.analysis import summary
    from weftsim.post.plots import plot_channels, plot_orbit
    from weftsim.post.results import save_npz

    outdir = prepare_directory(outdir, force, result.scene, kind="run")
    what = {"kind": "run", "engine": result.engine, "scene": result.scene.name, "status": result.status}
    files = {
        "channels": ("channels.csv", lambda target: write_csv(target, {n: result.samples[n] for n in result.channel_names})),
        "summary": ("summary.json", lambda target: write_json(target, summary(result))),
    }
    if npz:
        files["npz"] = ("result.npz", lambda target: write_atomic(target, lambda tmp: save_npz(result, tmp)))
    if figure and result.steps["time_s"].size:
        files["figure"] = ("channels.png", lambda target: write_figure(target, plot_channels([result])))
        if result.scene.loose_joints:  # one orbit panel per joint with a clearance (E, F)
            files["orbit"] = ("orbit.png", lambda target: write_figure(target, plot_orbit(result)))
        if "exchange_overlap_m" in result.steps:  # the weft exchange (weftsim.model.exchange)
            from weftsim.post.exchange_plot import plot_exchange

            files["exchange"] = ("exchange.png", lambda target: write_figure(target, plot_exchange(result)))
    return write_files(outdir, what, files, scene=result.scene, on_write=on_write)
