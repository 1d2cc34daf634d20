"""Contact-force outliers of the reference engine: a frequency study over scenes and tolerances.

After the start-up impact (revolution 1, from the centred journal) the peak contact force of a
revolution scatters by ~15 % (chaotic impact sequence, docs/hard-cases.md); a revolution that
peaks several times above the run's typical peak is a defect of the contact history, not
physics.  Two such defects are measured here from the raw solver rows:

- **onsets with a non-positive approach rate**: the penetration rate
  delta_dot = e_dot . e / |e| at a located onset must be > 0 (the journal enters the wall).
  An onset found at a separation instant has delta_dot < 0; it is then held at the floor
  v_min, and the damping term D = xi K delta^n delta_dot / v_imp of the Lankarani-Nikravesh
  family (Lankarani & Nikravesh 1990, J. Mech. Des. 112:369; Flores et al. 2011, Mech. Mach.
  Theory 46:1257) of the real re-impact that follows is hundreds of times too large;
- **negative penetration inside a contact segment**: a free flight that starts and ends inside
  one solver step is not seen when only the signs at step ends are tested.

Per run (:func:`measure`): the peak contact force of every revolution, their median over
revolutions 2..N, the worst ratio peak / median over revolutions 2..N, the largest |rapier
acceleration|, steps, wall time, the onsets with their approach rate and held impact velocity.
The CSV is written by ``scripts/contact_outliers.py``, the tables by :mod:`.outliers_report`.
"""

from __future__ import annotations

import csv
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.studies.common import StudyError

if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import TextIO

    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult

# The frequency study of the outliers: every paper scene at these tolerances (72 runs).
STUDY_RTOLS = {
    "DOP853": (1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
    "numba_DOP853": (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
}
# atol = rtol * 1e-3: the states (angles ~1 rad, rates ~10-100 rad/s) are resolved to rtol
# relative; this is the pair of the reproduction (rtol 1e-5, atol 1e-8).
ATOL_PER_RTOL = 1e-3
# The "method" of a flores-case row run on the Exudyn engine with the scene's own solver settings (its
# first-revolution peak against the reference engine's); it has no onset rates (they need the state).
EXUDYN = "exudyn"
STUDY_REVOLUTIONS = 10
OUTLIER_RATIOS = (1.5, 3.0)  # the thresholds the issue counts (peak / median of revolutions 2..N)

CSV_FIELDS_HEAD = ("scene", "method", "rtol", "atol", "overrides", "impact_velocity_rule", "status", "message",
                   "revolutions")  # fmt: skip
CSV_FIELDS_TAIL = (
    "median_peak_N", "worst_ratio", "worst_revolution", "max_abs_acceleration_m_s2",
    "max_abs_acceleration_after_rev1_m_s2", "steps", "wall_time_s", "onsets", "nonpositive_onsets",
    "engine_nonpositive_onsets", "onsets_below_floor", "min_onset_rate_m_s", "min_held_impact_velocity_m_s",
    "nonpositive_onset_angles_deg", "negative_penetration_rows_in_contact",
    "contact_segments_with_negative_penetration",
)  # fmt: skip


def csv_fields(revolutions: int = STUDY_REVOLUTIONS) -> tuple[str, ...]:
    """CSV columns: the run's identity, ``peak_rev1_N`` .. ``peak_revN_N``, then the measures."""
    return CSV_FIELDS_HEAD + tuple(f"peak_rev{k}_N" for k in range(1, revolutions + 1)) + CSV_FIELDS_TAIL


@dataclass(frozen=True)
class Cell:
    """One run of the study: a scene file, a reference-engine method and its tolerance."""

    scene_file: str
    method: str
    rtol: float
    revolutions: float = STUDY_REVOLUTIONS
    overrides: tuple = field(default_factory=tuple)  # ((dotted key, value), ...) in file units

    @property
    def atol(self) -> float:
        return self.rtol * ATOL_PER_RTOL

    @property
    def scene_name(self) -> str:
        return Path(self.scene_file).stem

    @property
    def overrides_text(self) -> str:
        return ";".join(f"{k}={v}" for k, v in self.overrides)

    @property
    def key(self) -> tuple[str, str, str, str]:
        """Identity of the cell in a CSV (for resuming): scene, method, rtol, overrides."""
        return (self.scene_name, self.method, f"{self.rtol:.0e}", self.overrides_text)

    def scene(self) -> Scene:
        from weftsim.input.scene import load_scene

        if self.method == EXUDYN:
            return load_scene(self.scene_file, {"drive.revolutions": self.revolutions, **dict(self.overrides)})
        overrides = {
            "solver.reference.method": self.method,
            "solver.reference.rtol": self.rtol,
            "solver.reference.atol": self.atol,
            "drive.revolutions": self.revolutions,
            **dict(self.overrides),
        }
        return load_scene(self.scene_file, overrides)


def _check_methods(methods, allowed=tuple(STUDY_RTOLS)) -> None:
    unknown = [m for m in methods if m not in allowed]
    if unknown:
        raise StudyError(f"--methods: unknown method(s) {unknown}; allowed: {sorted(allowed)}")


def study_cells(models: str | Path, methods: Sequence[str] | None = None, only: Sequence[str] | None = None,
                revolutions: float = STUDY_REVOLUTIONS,
                overrides: Sequence[tuple[str, object]] = ()) -> list[Cell]:  # fmt: skip
    """Cells of the study: ``models/paper/*.toml`` x :data:`STUDY_RTOLS`, compiled method first (fastest).

    ``methods``: subset of :data:`STUDY_RTOLS`; ``only``: keep scenes whose name contains one of these.
    """
    methods = list(methods or STUDY_RTOLS)
    _check_methods(methods)
    files = sorted((Path(models) / "paper").glob("*.toml"))
    if not files:
        raise StudyError(f"no scene files in {Path(models) / 'paper'}; run from the repository root or pass --models")
    if only:
        files = [f for f in files if any(part in f.stem for part in only)]
        if not files:
            raise StudyError(f"--only {' '.join(only)}: matches none of the paper scenes")
    order = sorted(methods, key=lambda m: not m.startswith("numba"))
    return [Cell(str(f), m, rtol, revolutions, tuple(overrides))
            for m in order for f in files for rtol in STUDY_RTOLS[m]]  # fmt: skip


def flores_cells(models: str | Path, methods: Sequence[str] = ("numba_DOP853", "DOP853"), rtol: float = 1e-9,
                 revolutions: float = STUDY_REVOLUTIONS,
                 overrides: Sequence[tuple[str, object]] = ()) -> list[Cell]:  # fmt: skip
    """The flores ce = 0.3 case: the reference scene with ``flores`` at restitution 0.3, each
    impact-velocity rule (``onset``, the literature's; ``max_approach``, the largest approach rate
    since the onset), unless ``overrides`` sets the rule.  rtol 1e-9 (atol 1e-12) is the reference
    scene's own tolerance, at which docs/hard-cases.md found the 1.13 MN lasting-contact peak.
    ``methods`` may include :data:`EXUDYN` (the Exudyn engine at the scene's own settings).
    """
    _check_methods(methods, (*STUDY_RTOLS, EXUDYN))
    path = Path(models) / "reference.toml"
    if not path.is_file():
        raise StudyError(f"scene file {path} not found; run from the repository root or pass --models")
    given = dict(overrides)
    rules = [given.pop("joint_e.impact_velocity_rule")] if "joint_e.impact_velocity_rule" in given else [
        "onset", "max_approach"]  # fmt: skip
    base = (("joint_e.law", "flores"), ("joint_e.restitution", 0.3))
    return [Cell(str(path), m, rtol, revolutions, (*base, ("joint_e.impact_velocity_rule", rule), *given.items()))
            for rule in rules for m in methods]  # fmt: skip


def peak_ratios(peaks: Sequence[float], skip: int = 1) -> tuple[float, float, int]:
    """Median of the per-revolution peaks after the first ``skip``, and the worst ratio to it.

    Parameters
    ----------
    peaks : sequence of float
        Peak contact force of revolutions 1..N, N.
    skip : int
        Revolutions left out (the first holds the start-up impact from the centred journal).

    Returns
    -------
    median, worst ratio max_k peak_k / median (k > skip), worst revolution (1-based); NaN, NaN, 0
    if no revolution is left.
    """
    later = np.asarray(peaks, dtype=float)[skip:]
    if later.size == 0:
        return math.nan, math.nan, 0
    median = float(np.median(later))
    worst = int(np.argmax(later))
    ratio = float(later[worst] / median) if median > 0.0 else math.nan  # no contact after revolution 1
    return median, ratio, skip + worst + 1


@dataclass(frozen=True)
class Onsets:
    """Contact onsets of a run: time (s), approach rate delta_dot at the onset and held v_imp (m/s)."""

    time_s: np.ndarray
    approach_rate_m_s: np.ndarray
    held_impact_velocity_m_s: np.ndarray


def onset_rows(contact: np.ndarray) -> np.ndarray:
    """Indices of the rows that start a contact segment (contact mode after a free-flight row)."""
    c = np.asarray(contact, dtype=bool)
    return np.flatnonzero(c[1:] & ~c[:-1]) + 1


def onsets(scene: Scene, t: np.ndarray, y: np.ndarray, contact: np.ndarray, impact: np.ndarray) -> Onsets:
    """Onsets of a reference-engine run from its raw step rows (see ``observe`` of
    :func:`weftsim.reference.solve`), with the approach rate of the state at each onset.

    The rate is :func:`weftsim.model.dynamics.penetration` of the located onset state,
    the quantity the engine floors and holds, so the check does not depend on the engine's
    own bookkeeping.
    """
    from weftsim.model.dynamics import ChainConstants, penetration

    p = ChainConstants.from_scene(scene)
    rows = onset_rows(contact)
    rates = np.array([penetration(p, float(t[i]), y[i])[1] for i in rows])
    return Onsets(np.asarray(t, dtype=float)[rows], rates, np.asarray(impact, dtype=float)[rows])


def negative_penetration_in_contact(contact: np.ndarray, penetration: np.ndarray) -> tuple[int, int]:
    """Rows in a contact segment with delta < 0, and the number of contact segments that hold any.

    Each such segment had a free flight that started and ended between two step ends (a
    missed separation); segments whose dip falls between the recorded rows are not counted,
    so this is a lower bound.
    """
    c = np.asarray(contact, dtype=bool)
    bad = c & (np.asarray(penetration) < 0.0)
    segment = np.cumsum(np.concatenate([[0], (c[1:] & ~c[:-1]).astype(int)]))
    return int(bad.sum()), int(np.unique(segment[bad]).size)


def revolution_peaks(result: RunResult, channel: str = "contact_force_N") -> list[float]:
    """Peak (max) of a channel in every complete revolution of the run."""
    from weftsim.post.analysis import complete_revolutions, peaks

    return [peaks(result, k)[channel]["max"] for k in range(complete_revolutions(result))]


def _quiet(text: str) -> None:
    """A cell's before-run warnings: the study counts onsets, not the design checks."""


def measure(cell: Cell) -> dict:
    """Run one cell and return its CSV row (see :func:`csv_fields`); an :data:`EXUDYN` cell has
    the peak and cost columns only."""
    from weftsim.engines import simulate

    scene = cell.scene()
    if cell.method == EXUDYN:
        return _peak_columns(cell, scene, simulate(scene, "exudyn", on_warning=_quiet))
    raw: dict = {}

    def keep(t, y, contact, impact):
        raw.update(t=t, y=y, contact=contact, impact=impact)

    result = simulate(scene, "reference", observe=keep, on_warning=_quiet)
    if not raw:
        raise StudyError(f"{cell.scene_name}: the reference engine gave no step states (ideal joint?)")
    row = _peak_columns(cell, scene, result)
    found = onsets(scene, raw["t"], raw["y"], raw["contact"], raw["impact"])
    # result.steps holds one row per raw row (both reference paths build its channels from them)
    if result.steps["time_s"].size != raw["t"].size:
        raise StudyError(f"{cell.scene_name}: {result.steps['time_s'].size} step channels for {raw['t'].size} states")
    neg_rows, neg_segments = negative_penetration_in_contact(raw["contact"], result.steps["penetration_m"])
    nonpositive = found.approach_rate_m_s <= 0.0
    engine_count = result.solver_stats.get("nonpositive_onsets", result.events.get("nonpositive_onsets"))
    omega = scene.drive.speed
    row.update({
        "onsets": int(found.time_s.size), "nonpositive_onsets": int(nonpositive.sum()),
        "engine_nonpositive_onsets": "" if engine_count is None else int(engine_count),
        "onsets_below_floor": int((found.approach_rate_m_s < scene.joint.min_impact_velocity).sum()),
        "min_onset_rate_m_s": float(found.approach_rate_m_s.min()) if found.time_s.size else math.nan,
        "min_held_impact_velocity_m_s": float(found.held_impact_velocity_m_s.min()) if found.time_s.size else math.nan,
        "nonpositive_onset_angles_deg": " ".join(f"{math.degrees(omega * t):.2f}" for t in found.time_s[nonpositive]),
        "negative_penetration_rows_in_contact": neg_rows,
        "contact_segments_with_negative_penetration": neg_segments,
    })  # fmt: skip
    return row


def _peak_columns(cell: Cell, scene, result) -> dict:
    """The columns of a row that need only the channels: identity, status, peaks, cost."""
    from weftsim.post.analysis import complete_revolutions

    peaks = revolution_peaks(result)
    median, worst, worst_rev = peak_ratios(peaks)
    acc = np.abs(result.steps["rapier_acceleration_m_s2"])
    later = result.steps["time_s"] >= scene.drive.period
    row = {
        "scene": cell.scene_name, "method": cell.method, "rtol": f"{cell.rtol:.0e}", "atol": f"{cell.atol:.0e}",
        "overrides": cell.overrides_text, "impact_velocity_rule": scene.joint.impact_velocity_rule,
        "status": result.status, "message": result.message, "revolutions": complete_revolutions(result),
        "median_peak_N": median, "worst_ratio": worst, "worst_revolution": worst_rev,
        "max_abs_acceleration_m_s2": float(acc.max()) if acc.size else math.nan,
        "max_abs_acceleration_after_rev1_m_s2": float(acc[later].max()) if later.any() else math.nan,
        "steps": result.solver_stats.get("steps"), "wall_time_s": round(result.wall_time_s, 2),
    }  # fmt: skip
    for k in range(int(math.ceil(cell.revolutions))):
        row[f"peak_rev{k + 1}_N"] = peaks[k] if k < len(peaks) else math.nan
    return row


def _measure_logged(cell: Cell) -> dict:
    try:
        return measure(cell)
    except Exception as exc:  # noqa: BLE001 - one bad cell is a row, not the end of the study
        return {"scene": cell.scene_name, "method": cell.method, "rtol": f"{cell.rtol:.0e}",
                "atol": f"{cell.atol:.0e}", "overrides": cell.overrides_text, "status": "error",
                "message": f"{type(exc).__name__}: {exc}"}  # fmt: skip


def row_key(row: dict) -> tuple[str, str, str, str]:
    return (row["scene"], row["method"], row["rtol"], row.get("overrides", ""))


def read_rows(path: str | Path) -> list[dict]:
    """Rows of a study CSV (strings), [] if it does not exist."""
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def write_rows(path: str | Path, rows: list[dict], revolutions: int = STUDY_REVOLUTIONS) -> None:
    """Write the rows sorted by scene, method, rtol (atomically: a temporary file, then renamed)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.part")
    order = sorted(rows, key=lambda r: (r["scene"], r["method"], -float(r["rtol"]), r.get("overrides", "")))
    with tmp.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=csv_fields(revolutions), extrasaction="ignore")
        writer.writeheader()
        for row in order:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    tmp.replace(path)


def run_study(cells: list[Cell], csv_path: str | Path, jobs: int = 1, force: bool = False,
              stream: TextIO | None = None) -> list[dict]:
    """Run the cells not yet in ``csv_path`` (all with ``force``), updating the CSV after each run.

    A progress line per finished run goes to ``stream`` (stderr).  ``jobs`` processes (1 or 2).
    """
    stream = stream or sys.stderr
    if jobs not in (1, 2):
        raise StudyError(f"--jobs must be 1 or 2 (the study machine has 2 shared cores), got {jobs}")
    revolutions = int(math.ceil(max([c.revolutions for c in cells], default=STUDY_REVOLUTIONS)))
    rows = {row_key(r): r for r in read_rows(csv_path)}
    todo = [c for c in cells if force or c.key not in rows]
    stream.write(f"contact outliers: {len(todo)} of {len(cells)} runs to do ({len(cells) - len(todo)} in {csv_path})\n")
    start = time.perf_counter()

    def done(i, row):
        rows[row_key(row)] = row
        write_rows(csv_path, list(rows.values()), revolutions)
        ratio = row.get("worst_ratio", math.nan)
        stream.write(f"[{i}/{len(todo)}] {row['scene']} {row['method']} rtol {row['rtol']}: {row['status']}, "
                     f"worst {float(ratio):.2f}x, {row.get('nonpositive_onsets', '?')} nonpositive onsets, "
                     f"{row.get('steps', '?')} steps, {row.get('wall_time_s', '?')} s "
                     f"(elapsed {time.perf_counter() - start:.0f} s)\n")  # fmt: skip
        stream.flush()

    if jobs == 1:
        for i, cell in enumerate(todo, 1):
            done(i, _measure_logged(cell))
    else:
        from concurrent.futures import ProcessPoolExecutor, as_completed

        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(_measure_logged, c) for c in todo]
            for i, future in enumerate(as_completed(futures), 1):
                done(i, future.result())
    return [rows[c.key] for c in cells if c.key in rows]
