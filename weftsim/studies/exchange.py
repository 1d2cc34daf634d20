"""The weft exchange's errors over the giver's clearance x crank speed (``weftsim study exchange``;
docs/rapier-tape.md section 7).

Each cell is one run of the loom (models/loom.toml, or the scene given: ``weftsim study exchange loom_tape`` for
the flexible tape) with an ``[exchange]``: the giver's clearance at E and the crank speed of the cell, the taker a
new joint (the scene's own clearance at E, or ``exchange.taker_clearance_mm`` given as an override) on the same
crank.  The cells run on the sweep machinery (:mod:`weftsim.sweep`: validated before the first runs, resumable,
one directory each under ``cells/``); each cell's ``summary.json`` holds its ``exchange`` block, from which the
table gives per transfer window (1: the start-up revolution; 2 on: running) the overlap and the relative speed at
the dead centre, their largest departures from the ideal mechanism over the window, and each head's position error.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from weftsim.studies import common

SPEEDS_RPM = (300.0, 600.0, 800.0)
CLEARANCES_MM = (0.02, 0.05, 0.1, 0.25)
REVOLUTIONS = 2.0
SCENE = "loom"  # models/loom.toml when installed, else the bundled loom
SETS = {"drive.speed_rpm": "it varies the crank speed", "joint_e.clearance_mm": "it varies the giver's clearance",
        "exchange.enabled": "it computes the exchange"}
CELLS = "cells"  # the sweep's directory inside the study's
COLUMNS = ("overlap_at_dead_centre_m", "overlap_error_max_abs_m", "relative_speed_at_dead_centre_m_s",
           "relative_speed_error_max_abs_m_s", "giver_error_at_dead_centre_m", "giver_error_min_m",
           "giver_error_max_m", "taker_error_at_dead_centre_m")


def _text(key: str, value: Any) -> str:
    """A scene key and value as a sweep's ``--set KEY=VALUE`` text."""
    if isinstance(value, bool):
        return f"{key}={'true' if value else 'false'}"
    if isinstance(value, (list, tuple)):
        return f"{key}={','.join(repr(v) for v in value)}"
    return f"{key}={value!r}" if isinstance(value, float) else f"{key}={value}"


def _source(models: str | Path, scene: str | Path | None) -> str:
    if scene is not None:
        return str(scene)
    installed = Path(models) / f"{SCENE}.toml"
    return str(installed) if installed.is_file() else SCENE


def _cell_rows(cell_dir: Path, speed: float, clearance: float, taker: float) -> list[dict]:
    """One row per transfer window of a cell's ``summary.json`` (one row saying why for a failed cell)."""
    base: dict[str, Any] = {"speed_rpm": speed, "clearance_mm": clearance, "taker_clearance_mm": taker}
    try:
        data = json.loads((cell_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return [{**base, "transfer": None, "status": "failed", **{k: None for k in COLUMNS}}]
    block = data.get("exchange") or {}
    status = "success" if data.get("complete") else "failed"
    rows = [{**base, "transfer": t["revolution"], "status": status, **{k: t[k] for k in COLUMNS}}
            for t in block.get("transfers", [])]
    return rows or [{**base, "transfer": None, "status": status, **{k: None for k in COLUMNS}}]


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the exchange study into ``outdir``; returns what ``exchange.json`` holds.

    ``overrides``: scene keys (file units) applied to every cell, except speed, the giver's clearance and
    ``exchange.enabled`` (:data:`SETS`); ``exchange.taker_clearance_mm`` sets the taker (default: the scene's own
    clearance at E, a new joint), ``exchange.overlap_mm`` and ``exchange.window_deg`` the transfer.
    """
    from weftsim.errors import SweepError
    from weftsim.input.scene import load_scene
    from weftsim.post.output import write_csv, write_figure, write_json
    from weftsim.sweep import plan_sweep, run_sweep

    overrides = common.study_overrides("exchange", SETS, revolutions, REVOLUTIONS, overrides)
    source = _source(models, scene)
    plain = load_scene(source, overrides)
    taker = overrides.get("exchange.taker_clearance_mm", common.clearance_mm(plain))
    fixed = {**overrides, "exchange.enabled": True, "exchange.taker_clearance_mm": taker}
    base_scene = load_scene(source, fixed)
    outdir = common.open_directory(outdir, force, base_scene)
    vary = [f"drive.speed_rpm={','.join(f'{v:g}' for v in SPEEDS_RPM)}",
            f"joint_e.clearance_mm={','.join(f'{v:g}' for v in CLEARANCES_MM)}"]
    try:
        plan = plan_sweep(source, vary, [_text(k, v) for k, v in fixed.items()], "reference")
        sweep = run_sweep(plan, outdir / CELLS, jobs=1, progress=progress)
    except SweepError as exc:
        raise common.StudyError(f"the exchange study's cells: {exc}") from None
    rows = []
    for planned in plan.cells:
        speed, clearance = planned.overrides["drive.speed_rpm"], planned.overrides["joint_e.clearance_mm"]
        rows += _cell_rows(outdir / CELLS / planned.cell.name, speed, clearance, taker)
    table = {key: [math.nan if row[key] is None else row[key] for row in rows] for key in rows[0] if key != "status"}
    written = {"csv": write_csv(outdir / "exchange.csv", table)}
    written["figure"] = write_figure(outdir / "study-exchange.png", exchange_figure(rows, base_scene.name, taker))
    report = {"study": "exchange", "scene": base_scene.name, **common.record(base_scene, overrides),
              "revolutions": overrides["drive.revolutions"], "taker_clearance_mm": taker,
              "overlap_mm": base_scene.exchange.overlap * 1e3 if base_scene.exchange else None,
              "cells_succeeded": sweep.succeeded + sweep.skipped, "cells_failed": sweep.failed, "rows": rows,
              "files": sorted(p.name for p in written.values()) + ["exchange.json"]}
    written["json"] = write_json(outdir / "exchange.json", report)
    common.finish(outdir, written, "exchange", base_scene)
    return report


def exchange_figure(rows: list[dict], scene_name: str, taker: float):
    """Four panels over the giver's clearance, one line per speed (solid: the last transfer, running; dashed: the
    first, after the start-up): the giver's error and the overlap's departure at the dead centre, the relative
    speed there and its largest departure from the ideal over the window."""
    from weftsim.post.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 7.6), sharex=True)
    panels = (("giver_error_at_dead_centre_m", 1e3, "giver head error at dead centre [mm]"),
              ("overlap_error_max_abs_m", 1e3, "largest overlap departure in the window [mm]"),
              ("relative_speed_at_dead_centre_m_s", 1.0, "relative speed at dead centre [m/s]"),
              ("relative_speed_error_max_abs_m_s", 1.0, "largest relative speed departure [m/s]"))
    speeds = sorted({r["speed_rpm"] for r in rows})
    transfers = sorted({r["transfer"] for r in rows if r["transfer"] is not None})
    colours = dict(zip(speeds, ("tab:blue", "tab:orange", "tab:red", "tab:green", "tab:purple")))
    for ax, (key, scale, label) in zip(axes.flat, panels):
        for rpm in speeds:
            for transfer in transfers[:1] + transfers[-1:] if len(transfers) > 1 else transfers:
                cells = [r for r in rows if r["speed_rpm"] == rpm and r["transfer"] == transfer and r[key] is not None]
                last = transfer == transfers[-1]
                ax.plot([r["clearance_mm"] for r in cells], [r[key] * scale for r in cells], "o-" if last else "x--",
                        color=colours.get(rpm, "k"), lw=1.4 if last else 0.8,
                        label=f"{rpm:g} rpm, transfer {transfer}")
        ax.set_ylabel(label)
        ax.set_xscale("log")
        clearances = sorted({r["clearance_mm"] for r in rows})
        ax.set_xticks(clearances, [f"{c:g}" for c in clearances])
        ax.minorticks_off()
        ax.grid(alpha=0.3, which="both")
    for ax in axes[1]:
        ax.set_xlabel("giver's radial clearance at E [mm]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f"weft exchange over clearance x speed ({scene_name}, reference engine, taker c = {taker:g} mm)")
    fig.tight_layout()
    return fig


def format_report(report: dict) -> str:
    """The table ``weftsim study exchange`` prints."""
    lines = [f"weft exchange, scene {report['scene']}, {report['revolutions']:g} revolutions, taker c = "
             f"{report['taker_clearance_mm']:g} mm, overlap {report['overlap_mm']:g} mm (ideal), reference engine",
             f"{'rpm':>5s} {'c mm':>6s} {'xfer':>4s} {'overlap mm':>10s} {'d over mm':>9s} {'w m/s':>8s} "
             f"{'d w m/s':>8s} {'e_g mm':>8s} {'e_t mm':>8s}"]

    def mm(value):
        return "-" if value is None else f"{value * 1e3:.4g}"

    def plain(value):
        return "-" if value is None else f"{value:.4g}"

    for r in report["rows"]:
        lines.append(f"{r['speed_rpm']:5.0f} {r['clearance_mm']:6.3g} {str(r['transfer']):>4s} "
                     f"{mm(r['overlap_at_dead_centre_m']):>10s} {mm(r['overlap_error_max_abs_m']):>9s} "
                     f"{plain(r['relative_speed_at_dead_centre_m_s']):>8s} "
                     f"{plain(r['relative_speed_error_max_abs_m_s']):>8s} {mm(r['giver_error_at_dead_centre_m']):>8s} "
                     f"{mm(r['taker_error_at_dead_centre_m']):>8s}")
    return "\n".join(lines)
