"""Report of the work-precision benchmark (:mod:`weftsim.bench`): JSON, Markdown tables, figures.

Figures (one per case, ``bench-<case>.png``): error against wall time, log-log, one series
per engine family, its points joined from the coarsest to the finest setting; failed runs are
drawn as crosses at the top edge; dashed lines mark
the targets (1 % peaks, 2 % statistics), the dotted line the converged ensemble's own
spread (the error floor), the vertical line real time (wall time = loom time).
"""

from __future__ import annotations

import os
import platform
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FAILED_Y = 1.0  # where failed runs are drawn (relative error 100 %)


def machine_info() -> dict:
    """CPU, cores, load average, OS, Python and package versions, git commit (:mod:`weftsim.post.provenance`,
    as ``summary.json`` records them)."""
    cpu = platform.processor() or "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    from weftsim.post import provenance

    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "versions": provenance.versions(),  # from package metadata: nothing imported for it
        "git_commit": provenance.commit(),
    }


def _e(value) -> str:
    return "-" if value is None else f"{value:.1e}"


def _status(row) -> str:
    if row["status"] == "success":
        return "ok"
    return f"**failed** ({row.get('failure') or 'solver'})"


def best_settings(report: dict, case: str = "c0.25mm-400rpm") -> dict:
    """Per engine family: the fastest run meeting both targets on ``case`` (or None)."""
    out: dict[str, Any] = {}
    runs = report["cases"].get(case, {}).get("runs", [])
    for row in runs:
        err = row["errors"] or {}
        ok = (row["status"] == "success" and err.get("peak_max") is not None
              and err["peak_max"] < report["targets"]["peak"]
              and err.get("stats_max") is not None and err["stats_max"] < report["targets"]["stats"])  # fmt: skip
        if not ok:
            continue
        key = row["family"]
        if key not in out or row["realtime_ratio"] > out[key]["realtime_ratio"]:
            out[key] = row
    return out


def markdown(report: dict) -> str:
    """The tables of docs/performance.md: machine, start-up, converged solutions, every run."""
    m = report["machine_start"]
    lines = [f"Mode {report['mode']}: {report['revolutions']:g} revolutions per run, wall time = median of "
             f"{report['repeats']} runs (runs longer than {report['repeat_limit_s']:g} s timed on "
             f"{report['timing_revolutions']:g} revolution), total {report['total_time_s']:.0f} s.", "",
             f"Machine: {m['cpu']}, {m['cores']} cores, {m['platform']}, load average at start "
             f"{', '.join(f'{x:.1f}' for x in m['load_average'] or [])}, at end "
             f"{', '.join(f'{x:.1f}' for x in report['machine_end']['load_average'] or [])}; Python {m['python']}, "
             + ", ".join(f"{k} {v}" for k, v in m["versions"].items()) + f"; weftsim {m['git_commit']}.", ""]  # fmt: skip
    lines += ["| start-up | import, s | first call, s | second call, s |", "|---|---|---|---|"]
    for name, s in report["startup"].items():
        lines.append(f"| {name} | {s['import_s']:.2f} | {s['first_call_s']:.3f} | {s['second_call_s']:.3f} |")
    for case, data in report["cases"].items():
        ref = data["converged"]
        lines += ["", f"### {case}", "",
                  f"Converged: peaks {', '.join(f'{k} {v:.6g}' for k, v in ref['peak'].items())}; first contact "
                  f"{ref['first_contact_deg']:.6f} deg; ensemble spread (error floor) peaks {_e(ref['floor']['peak'])}, "
                  f"statistics {_e(ref['floor']['stats'])}.", "",
                  "| engine setting | status | wall, s | CPU, s | timed | x real time | steps | rejected "
                  "| peak err | stats err | contact angle err, deg |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
        for row in data["runs"]:
            t = row["timing"]
            err = row["errors"] or {}
            timed = f"{t['runs']}x{t['revolutions']:g} rev"
            lines.append(
                f"| {row['setting']} | {_status(row)} | {row['wall_s']:.3g} | "
                f"{t['cpu_median_s'] * row['loom_time_s'] / t['loom_time_s']:.3g} | {timed} | "
                f"{row['realtime_ratio']:.3g} | {row['steps']} | {row['rejected_steps']} | {_e(err.get('peak_max'))} | "
                f"{_e(err.get('stats_max'))} | {_e(err.get('first_contact_deg'))} |"
            )  # fmt: skip
        failed = [r for r in data["runs"] if r["status"] != "success"]
        if failed:
            lines += ["", "Failed runs:", ""]
            lines += [f"- {r['setting']}: {r['message']}" for r in failed]
    return "\n".join(lines) + "\n"


def figure(report: dict, case: str) -> Figure:
    """Error against wall time (log-log) for one case: peaks and statistics panels."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = report["cases"][case]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5), sharex=True)
    families = list(dict.fromkeys(r["family"] for r in data["runs"]))  # in run order
    styles: dict[str, dict[str, str]] = {}
    palettes = {"reference": ["tab:blue", "tab:cyan", "navy", "slateblue", "steelblue"],
                "exudyn tree": ["tab:red", "tab:orange", "salmon", "brown"],
                "exudyn rigid_body": ["tab:green", "olive", "limegreen"]}  # fmt: skip
    markers = ["o", "s", "^", "v", "D"]
    for fam in families:
        group = next(g for g in palettes if fam.startswith(g))
        k = sum(1 for f in styles if f.startswith(group))
        styles[fam] = {"color": palettes[group][k % len(palettes[group])], "marker": markers[k % len(markers)]}
    for panel, (key, title, target) in enumerate((("peak_max", "first-revolution maxima", "peak"),
                                                   ("stats_max", "RMS and mean, revolutions 2..N", "stats"))):  # fmt: skip
        ax = axes[panel]
        for fam in families:
            rows = [r for r in data["runs"] if r["family"] == fam]  # tolerance or step from coarse to fine
            ok = [r for r in rows if r["status"] == "success" and (r["errors"] or {}).get(key) is not None]
            style = {**styles[fam], "ms": 5, "lw": 1}
            ax.plot([r["wall_s"] for r in ok], [max(r["errors"][key], 1e-9) for r in ok], label=fam, **style)
            bad = [r for r in rows if r not in ok]
            if bad:
                ax.plot([r["wall_s"] for r in bad], [FAILED_Y] * len(bad), "x", color=style["color"], ms=8)
        floor = data["converged"]["floor"].get(target)
        ax.axhline(report["targets"][target], color="k", ls="--", lw=0.8)
        if floor:
            ax.axhline(floor, color="gray", ls=":", lw=1.0)
        loom = report["revolutions"] * 60.0 / float(case.split("-")[1].replace("rpm", ""))
        ax.axvline(loom, color="gray", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"wall time for {report['revolutions']:g} revolutions, s (grey line: real time)")
        ax.set_ylabel("largest relative error")
        ax.set_title(f"{case}: {title}")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle("work-precision (x: failed run; dashed: target; dotted: spread of the converged solutions)",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    return fig


def write_report(report: dict, outdir: str | Path, force: bool = False) -> list[Path]:
    """bench.json, bench.md and one figure per case into ``outdir``; returns the files."""
    from weftsim.post.output import (begin_directory, finish_directory, prepare_directory, write_figure, write_json,
                                     write_text)

    outdir = prepare_directory(outdir, force, kind="bench")
    begin_directory(outdir, {"kind": "bench", "mode": report["mode"]})
    written = {"md": write_text(outdir / "bench.md", markdown(report))}
    for case in report["cases"]:
        written[case] = write_figure(outdir / f"bench-{case.replace('.', 'p')}.png", figure(report, case))
    report["best"] = {case: {fam: row["setting"] for fam, row in best_settings(report, case).items()}
                      for case in report["cases"]}  # fmt: skip
    written["json"] = write_json(outdir / "bench.json", report)
    finish_directory(outdir, written, {"kind": "bench", "mode": report["mode"]})
    return sorted(written.values())

