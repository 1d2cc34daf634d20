"""The bundled loom's life in its three regimes, one figure (docs/wear.md section 12, docs/img/loom_life.png).

    python scripts/loom_life.py LABEL=DIR [LABEL=DIR ...] [-o docs/img/loom_life.png]

Each DIR is the output directory of a ``weftsim wear ... --uncertain ...`` ensemble (the commands of
docs/wear.md section 12), LABEL its name in the figure; nothing is simulated here.  Left: the distribution of the running hours to the limit
(each curve ends at the fraction of the samples that reach it within the ensemble's horizon).  Right: p10 - p90
of the calendar days to the limit at one, two and three shifts (8, 16, 24 h a day), p50 marked.  No published
bushing replacement interval of a loom was found to draw beside them (section 12 says where it was looked for).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _read(directory: Path) -> tuple[dict, np.ndarray]:
    data = json.loads((directory / "ensemble.json").read_text())
    with open(directory / "ensemble.csv", newline="") as f:
        hours = np.array([float(row["hours_to_limit_e"]) for row in csv.DictReader(f)])
    return data, hours


def main() -> None:
    from weftsim.post.output import write_figure
    from weftsim.post.plots import figure

    ap = argparse.ArgumentParser()
    ap.add_argument("ensembles", nargs="+", help="LABEL=DIR")
    ap.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "img" / "loom_life.png")
    args = ap.parse_args()
    cases = []
    for text in args.ensembles:
        label, _, directory = text.rpartition("=")
        data, hours = _read(Path(directory))
        cases.append((label or data["scene"], data, hours))
    limit = cases[0][1]["limit_clearance_mm"]
    fig = figure(figsize=(11, 4.4))
    ax = fig.add_subplot(1, 2, 1)
    for i, (label, data, hours) in enumerate(cases):
        h = np.sort(hours)
        ok = np.isfinite(h)
        if ok.any():
            ax.step(h[ok], np.arange(1, ok.sum() + 1) / h.size, where="post", color=f"C{i}", label=label)
        else:
            ax.plot([], [], color=f"C{i}", label=f"{label}: none within {data['horizon_hours']:.3g} h")
    ax.set_xscale("log")
    ax.set_xlabel(f"running hours to an effective clearance of {limit:g} mm")
    ax.set_ylabel("fraction of the samples")
    ax.set_ylim(0.0, 1.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    ax = fig.add_subplot(1, 2, 2)
    key = f"{limit:.6g}"
    y = 0
    ticks, names, right = [], [], 0.0
    for i, (label, data, _) in enumerate(cases):
        for shift, table in (data.get("calendar_days_by_shift") or {}).items():
            q = {p: table[key][p]["hours"] for p in ("p10", "p50", "p90")}
            beyond = data["horizon_calendar_days_by_shift"][shift]
            low = q["p10"] if q["p10"] is not None else beyond
            high = q["p90"] if q["p90"] is not None else beyond
            ax.plot([low, high], [y, y], color=f"C{i}", lw=4, solid_capstyle="butt")
            if q["p50"] is not None:
                ax.plot([q["p50"]], [y], "k|", ms=12)
            if q["p90"] is None:
                ax.annotate("", xy=(high * 3.0, y), xytext=(high, y), arrowprops={"arrowstyle": "->", "color": f"C{i}"})
            right = max(right, 10.0 * high)
            ticks.append(y)
            names.append(f"{label}, {shift} h a day")
            y -= 1
        y -= 0.5
    ax.set_yticks(ticks, names, fontsize=7)
    ax.set_xscale("log")
    ax.set_xlim(right=right)
    ax.set_xlabel(f"calendar days to {limit:g} mm, 6 days a week: p10-p90, p50 |\n(arrow: beyond the horizon)")
    ax.grid(True, axis="x", alpha=0.3)
    ax.text(0.02, 0.30, "published replacement intervals of loom bushings:\nnone found (docs/wear.md section 12)",
            transform=ax.transAxes, fontsize=7, va="bottom")
    fig.suptitle("The bundled loom's pin at E, 600 rpm nominal: greased, truly dry and oiled")
    fig.tight_layout()
    write_figure(args.output, fig)
    print(f"wrote {args.output}")
    for label, data, hours in cases:
        share = data.get("stop_start_share") or {}
        print(f"{label}: reaching {limit:g} mm {100 * np.mean(np.isfinite(hours)):.3g} %; stop-start share median "
              f"{share.get('median', math.nan):.3g}")


if __name__ == "__main__":
    main()
