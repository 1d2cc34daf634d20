"""The optimisation directory: the problem (``problem.json``) and every evaluated design (``evaluations.jsonl``).

Layout::

    OUT/problem.json         base scene, engine, design keys, objectives, worn clearance: what the stored
                             evaluations are evaluations of
    OUT/evaluations.jsonl    one line per design whose objectives were evaluated, appended as each arrives
    OUT/sweep.lock           while an optimisation runs (weftsim.sweep.lock: one process per directory)
    OUT/optimum.json, designs.csv, convergence.png[, pareto.png]   the report (weftsim.optimize.report)

Resuming is replaying: differential evolution with the same seed proposes the same designs in the same
order, and a design already in ``evaluations.jsonl`` is answered from there instead of being run again, so an
interrupted optimisation, rerun, reaches the result the uninterrupted one would have.  A line that cannot
be read back (a line cut by a kill, a line edited by hand) is ignored and its design run again.  A directory
holding another problem is refused, naming what differs; the bounds, constraints, seed and budget are not
part of the problem (the same design has the same objectives under any of them).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

from weftsim.errors import OptimizeError

PROBLEM_FILE = "problem.json"
EVALUATIONS_FILE = "evaluations.jsonl"
PROBLEM_FORMAT = "weftsim-optimize/1"
MAX_PROBLEM_BYTES = 16 * 2**20
MAX_LINE_BYTES = 2**20


def problem_record(base_keys: dict, engine: str, variables: list[dict], objectives: tuple[str, ...],
                   at_clearance_mm: float | None) -> dict[str, Any]:
    from weftsim.version import __version__

    return {"format": PROBLEM_FORMAT, "base_scene": base_keys, "engine": engine,
            "design_keys": sorted(v["key"] for v in variables), "objectives": list(objectives),
            "at_clearance_mm": at_clearance_mm, "weftsim_version": __version__}


def _differences(old: dict, new: dict) -> list[str]:
    out = []
    for field in ("engine", "design_keys", "objectives", "at_clearance_mm"):
        if old.get(field) != new[field]:
            out.append(f"{field} {old.get(field)!r} there, {new[field]!r} here")
    base_old: dict = old["base_scene"] if isinstance(old.get("base_scene"), dict) else {}
    changed = sorted(k for k in set(base_old) | set(new["base_scene"]) if base_old.get(k) != new["base_scene"].get(k))
    if changed:
        shown = ", ".join(f"{k} = {base_old.get(k)!r} there, {new['base_scene'].get(k)!r} here" for k in changed[:3])
        out.append(f"base scene differs: {shown}" + (f" (and {len(changed) - 3} more)" if len(changed) > 3 else ""))
    return out


def open_store(outdir: Path, problem: dict) -> None:
    """Check ``outdir`` holds this problem or nothing of it; write ``problem.json`` (a new directory)."""
    from weftsim.post.output import write_json

    path = outdir / PROBLEM_FILE
    if path.exists() or path.is_symlink():
        if not path.is_file() or path.stat().st_size > MAX_PROBLEM_BYTES:
            raise OptimizeError(f"{path} is not an optimisation's problem file; move it away to optimise there")
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError):
            old = None
        if not isinstance(old, dict) or old.get("format") != PROBLEM_FORMAT:
            raise OptimizeError(f"{path} cannot be read as weftsim's problem file (damaged or edited); move it away "
                                "to start a new optimisation there")
        problems = _differences(old, problem)
        if problems:
            raise OptimizeError(f"output directory {outdir} holds another optimisation ({'; '.join(problems)}); "
                                "choose another output directory (-o) or remove that one")
        return
    write_json(path, problem)


def normalise(data: Any) -> Any:
    from weftsim.sweep.cell import normalise as as_read_back

    return as_read_back(data)


def _valid(line: dict, objectives: tuple[str, ...], n_keys: int) -> bool:
    values = line.get("values")
    found = line.get("objectives")
    if not isinstance(line.get("id"), str) or not isinstance(values, list) or len(values) != n_keys:
        return False
    if line["id"] != ",".join(repr(v) for v in values):  # an id that does not name its values: edited by hand
        return False
    if line.get("status") not in ("success", "failed") or not isinstance(found, dict):
        return False
    if set(found) != set(objectives):
        return False
    return all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v))
               for v in found.values())


def read_evaluations(outdir: Path, objectives: tuple[str, ...], n_keys: int) -> dict[str, dict]:
    """The stored evaluations by design id; unreadable or malformed lines are skipped (run again)."""
    path = outdir / EVALUATIONS_FILE
    if not path.is_file():
        return {}
    out: dict[str, dict] = {}
    with open(path, "rb") as f:
        for raw in f:
            if len(raw) > MAX_LINE_BYTES or not raw.endswith(b"\n"):
                continue  # a line cut by a kill has no newline
            try:
                line = json.loads(raw.decode("utf-8"))
            except (ValueError, RecursionError, UnicodeDecodeError):
                continue
            if isinstance(line, dict) and _valid(line, objectives, n_keys):
                out[line["id"]] = line
    return out


class EvaluationLog:
    """Appends one evaluated design a line to ``evaluations.jsonl`` (flushed and synced line by line)."""

    def __init__(self, outdir: Path):
        self.path = outdir / EVALUATIONS_FILE
        if self.path.exists() and not self.path.is_file():
            raise OptimizeError(f"{self.path} is not a file; move it away to optimise there")
        self.file = open(self.path, "ab")
        if self.file.tell() and not self._ends_with_newline():
            self.file.write(b"\n")  # end the line a kill cut, so the next line starts on its own

    def _ends_with_newline(self) -> bool:
        with open(self.path, "rb") as f:
            f.seek(-1, os.SEEK_END)
            return f.read(1) == b"\n"

    def append(self, entry: dict) -> None:
        from weftsim.post.output import to_json

        self.file.write(json.dumps(json.loads(to_json(entry)), separators=(",", ":")).encode("utf-8") + b"\n")
        self.file.flush()
        os.fsync(self.file.fileno())

    def close(self) -> None:
        self.file.close()
