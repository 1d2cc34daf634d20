"""Markdown reports of the contact-outlier study (:mod:`weftsim.studies.outliers`): the tables of
docs/hard-cases.md section 6, rendered from the study's CSV rows, and the marked section they replace.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from weftsim.studies.common import StudyError
from weftsim.studies.outliers import OUTLIER_RATIOS, row_key


def _float(row: dict, name: str) -> float:
    try:
        return float(row.get(name, ""))
    except (TypeError, ValueError):
        return math.nan


def later_peaks(row: dict, skip: int = 1) -> np.ndarray:
    """Peaks of revolutions skip+1..N of a CSV row (N from its ``revolutions``), N."""
    n = int(_float(row, "revolutions"))
    return np.array([_float(row, f"peak_rev{k}_N") for k in range(skip + 1, n + 1)])


def ensemble_ratios(rows: list[dict]) -> dict[tuple, float]:
    """Worst later peak of each successful run against its scene's ensemble median.

    The ensemble median is the median of the peaks of revolutions 2..N of all successful runs of
    the scene (every method and tolerance).  Unlike the run's own median it also flags a run
    whose contact history broke in its first half: from then on every revolution peaks high and
    the run's own median is itself an outlier value.
    """
    ok = [r for r in rows if r.get("status") == "success"]
    pooled: dict[str, list] = {}
    for r in ok:
        pooled.setdefault(r["scene"], []).extend(later_peaks(r))
    median = {scene: float(np.median(v)) for scene, v in pooled.items()}
    return {row_key(r): float(np.max(later_peaks(r))) / median[r["scene"]] for r in ok
            if later_peaks(r).size and median[r["scene"]] > 0.0}  # fmt: skip


def _counts(ratios) -> str:
    ratios = np.asarray(list(ratios), dtype=float)
    return ", ".join(f"**{int((ratios > x).sum())}** above {x:g}x" for x in OUTLIER_RATIOS)


def _onset_lines(rows: list[dict]) -> list[str]:
    lines = []
    for method in sorted({r["method"] for r in rows}):
        mine = [r for r in rows if r["method"] == method and r.get("status") == "success"]

        def total(name):
            return sum(int(_float(r, name)) for r in mine)

        counted = [r for r in mine if r.get("engine_nonpositive_onsets", "") != ""]
        engine = f"; the engine counts {total('engine_nonpositive_onsets')}" if len(counted) == len(mine) else ""
        lines.append(f"- `{method}`, {len(mine)} runs: **{total('nonpositive_onsets')}** onsets with a non-positive "
                     f"approach rate (in {sum(_float(r, 'nonpositive_onsets') > 0 for r in mine)} runs{engine}) of "
                     f"{total('onsets')} onsets; {total('contact_segments_with_negative_penetration')} contact "
                     "segments with a negative penetration at a recorded row inside (missed separations)")  # fmt: skip
    for r in rows:
        if r.get("status") != "success":
            lines.append(f"- {r.get('status')}: {r['scene']} `{r['method']}` rtol {r['rtol']}: {r.get('message', '')}")
    return lines


def markdown_report(rows: list[dict], command: str) -> str:
    """The frequency study as Markdown: outlier counts by both medians, onset defects, one line per run."""
    ok = [r for r in rows if r.get("status") == "success"]
    pooled = ensemble_ratios(rows)
    own = [_float(r, "worst_ratio") for r in ok]
    lines = [f"Regenerate: `{command}`", "",
             f"{len(rows)} runs, {len(ok)} successful.  Worst revolution after the first against the median of "
             f"the run's own revolutions 2..N: {_counts(own)} (largest {np.nanmax(own, initial=0.0):.2f}x); "
             f"against the scene's ensemble median (all its runs): {_counts(pooled.values())} (largest "
             f"{max(pooled.values(), default=0.0):.2f}x).", ""]  # fmt: skip
    lines += _onset_lines(rows)
    lines += ["", "| scene | method | rtol | worst / run median (rev) | worst / scene median | worst peak (N) | "
              "run median 2..N (N) | rev 1 peak (N) | max abs(a) (m/s²) | steps | wall (s) | onsets | "
              "non-positive onsets (crank angle, deg) | min onset rate (m/s) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in ok:
        ratio, rev, scene_ratio = _float(r, "worst_ratio"), r.get("worst_revolution", ""), pooled.get(row_key(r))
        own_cell = f"**{ratio:.2f}**" if ratio > OUTLIER_RATIOS[0] else f"{ratio:.2f}"
        scene = "" if scene_ratio is None else (f"**{scene_ratio:.2f}**" if scene_ratio > OUTLIER_RATIOS[0]
                                               else f"{scene_ratio:.2f}")  # fmt: skip
        angles = r.get("nonpositive_onset_angles_deg", "")
        lines.append(
            f"| {r['scene']} | {r['method']} | {r['rtol']} | {own_cell} ({rev}) | {scene} | "
            f"{np.max(later_peaks(r)):.3g} | {_float(r, 'median_peak_N'):.3g} | {_float(r, 'peak_rev1_N'):.3g} | "
            f"{_float(r, 'max_abs_acceleration_m_s2'):.3g} | {r['steps']} | {r['wall_time_s']} | {r['onsets']} | "
            f"{r['nonpositive_onsets']}{f' ({angles})' if angles else ''} | {_float(r, 'min_onset_rate_m_s'):.2g} |"
        )  # fmt: skip
    return "\n".join(lines) + "\n"


def flores_report(rows: list[dict], command: str) -> str:
    """The flores ce = 0.3 case as Markdown: first-revolution and later peaks per rule and method."""
    lines = [f"Regenerate: `{command}`", "",
             "| impact-velocity rule | method | rev 1 peak (N) | largest later peak (N, rev) | median of later "
             "peaks (N) | max abs(a) (m/s²) | steps | wall (s) | onsets | non-positive onsets |",
             "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        if r.get("status") != "success":
            lines.append(f"| {r.get('impact_velocity_rule', '')} | {r['method']} | {r.get('status')}: "
                         f"{r.get('message', '')} |||||||")  # fmt: skip
            continue
        later = later_peaks(r)
        lines.append(
            f"| {r['impact_velocity_rule']} | {r['method']} | {_float(r, 'peak_rev1_N'):.3g} | "
            f"{later.max():.3g} ({int(np.argmax(later)) + 2}) | {_float(r, 'median_peak_N'):.3g} | "
            f"{_float(r, 'max_abs_acceleration_m_s2'):.3g} | {r['steps']} | {r['wall_time_s']} | {r['onsets']} | "
            f"{r['nonpositive_onsets']} |"
        )  # fmt: skip
    return "\n".join(lines) + "\n"
def replace_section(doc: str | Path, name: str, body: str) -> None:
    """Put ``body`` between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` in ``doc``.

    The markers must be there already (the text around them is the author's), each once.
    """
    path = Path(doc)
    text = path.read_text()
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise StudyError(f"{path} must hold the markers {begin} and {end}, once each and in that order")
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    path.write_text(f"{head}{begin}\n{body}{end}{tail}")
