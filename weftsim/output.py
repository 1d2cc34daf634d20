"""Writing results to disk: atomic CSV, JSON and figure files.

Every file is written to a temporary name in the target directory and then
renamed over the final name, so a run that dies leaves either the complete
previous file or the complete new one, never half of one.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np

from weftsim.results import CHANNELS, RunResult


class OutputError(OSError):
    """The output directory or a file in it cannot be written."""


MANIFEST = ".weftsim-output.json"


def prepare_directory(path: str | Path, force: bool = False) -> Path:
    """Create ``path`` (and parents) and check it is a writable directory of ours.

    A directory that already holds files but no weftsim manifest was not written by
    weftsim: it is refused (unless ``force``) so a run never mixes its files with others.
    """
    path = Path(path)
    if path.is_dir() and not force and not (path / MANIFEST).exists() and any(path.iterdir()):
        raise OutputError(
            f"output directory {path} is not empty and was not written by weftsim; "
            "choose another directory with -o, or pass --force to write into it anyway"
        )
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"output directory {path} exists and is not a directory") from None
    except OSError as exc:
        raise OutputError(f"cannot create output directory {path}: {exc.strerror}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"output directory {path} is not writable")
    return path


def write_atomic(target: Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp_path)`` and rename the temporary file onto ``target``."""
    target = Path(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
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


def write_csv(target: Path, columns: dict[str, np.ndarray]) -> Path:
    """Columns of equal length, header = column names, full double precision."""
    names = list(columns)
    table = np.column_stack([np.asarray(columns[n], dtype=float) for n in names]) if names else np.zeros((0, 0))

    def write(tmp: Path) -> None:
        np.savetxt(tmp, table, delimiter=",", header=",".join(names), comments="", fmt="%.10g")

    return write_atomic(target, write)


def write_figure(target: Path, figure) -> Path:
    import sys

    try:
        return write_atomic(target, lambda p: figure.savefig(p, format=target.suffix.lstrip("."), dpi=130))
    finally:
        if "matplotlib.pyplot" in sys.modules:  # a pyplot figure: free it (weftsim.plots.figure() are not held)
            sys.modules["matplotlib.pyplot"].close(figure)


def _manifest_files(outdir: Path) -> set[str]:
    try:
        return set(json.loads((outdir / MANIFEST).read_text()).get("files", []))
    except (OSError, ValueError):
        return set()


def begin_directory(outdir: Path, what: dict) -> None:
    """Mark the directory as being written: a run killed between two files leaves this mark.

    Each file is atomic on its own; this manifest (``"state": "writing"``) tells a reader that
    the directory may hold a mix of the previous run's and this run's complete files.
    """
    write_json(outdir / MANIFEST, {**what, "state": "writing", "files": sorted(_manifest_files(outdir))})
    for leftover in outdir.glob(".*.part"):  # temporary files of a run that was killed while writing
        leftover.unlink(missing_ok=True)


def finish_directory(outdir: Path, written: dict[str, Path], what: dict) -> None:
    """Write the manifest last (``"state": "complete"``), then delete files an earlier run left.

    Afterwards the directory holds exactly this run's files (plus anything weftsim did not write).
    """
    old = _manifest_files(outdir)
    names = sorted(p.name for p in written.values())
    write_json(outdir / MANIFEST, {**what, "state": "complete", "files": names})
    for stale in old - set(names):
        if "/" not in stale and stale != MANIFEST:
            (outdir / stale).unlink(missing_ok=True)


def write_run(result: RunResult, outdir: str | Path, figure: bool = True, force: bool = False) -> dict[str, Path]:
    """Write ``channels.csv``, ``summary.json`` and ``channels.png`` for one run, atomically each."""
    from weftsim.analysis import summary
    from weftsim.plots import plot_channels

    outdir = prepare_directory(outdir, force)
    what = {"kind": "run", "engine": result.engine, "scene": result.scene.name, "status": result.status}
    begin_directory(outdir, what)
    written = {
        "channels": write_csv(outdir / "channels.csv", {n: result.samples[n] for n in CHANNELS}),
        "summary": write_json(outdir / "summary.json", summary(result)),
    }
    if figure and result.steps["time_s"].size:
        written["figure"] = write_figure(outdir / "channels.png", plot_channels([result]))
    finish_directory(outdir, written, what)
    return written
