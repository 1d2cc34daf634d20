"""Regime map of the lubricated joint at E: minimum film ratio and peak force over crank speed x
clearance x viscosity (``weftsim study regime``; docs/lubricated-joint.md).

Each cell is one reference-engine run of :data:`REVOLUTIONS` revolutions of the loom (models/loom.toml; the
reference mechanism when that scene is not installed, as the report says) with a ``[joint_e.lubrication]``
table of the cell's viscosity and the default roughness (0.4 um combined RMS), beside a dry run at the
same speed and clearance.  The steady revolution (the last) gives

- the minimum film ratio Lambda = h_min / sigma, and the regime it puts the joint in: hydrodynamic
  (Lambda > 3: the film separates the surfaces), mixed (1 <= Lambda <= 3: the asperities carry part of
  the load) or dry (Lambda < 1: the film is at its floor, solid contact);
- the peak joint force: film + asperity + dry law (their magnitudes summed), against the dry joint's
  contact force;
- the run time per revolution, lubricated against dry.

The first revolution is left out: it starts from the centred journal (a start-up transient).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from weftsim.studies import common

SPEEDS_RPM = (300.0, 600.0, 800.0)
CLEARANCES_MM = (0.02, 0.05, 0.1, 0.25)
VISCOSITIES_MPA_S = (20.0, 80.0, 320.0)  # ISO VG 220 at ~100 C, ~60 C, ~30 C
REVOLUTIONS = 2.0
HYDRODYNAMIC, MIXED = 3.0, 1.0  # film ratio limits of the regimes
FLOOR_DRAWN = 0.3  # the figure's lowest film ratio
SETS = {"drive.speed_rpm": "it varies the crank speed", "joint_e.clearance_mm": "it varies the clearance at E",
        "joint_e.lubrication.viscosity_mpa_s": "it varies the viscosity"}
SCENES = ("loom.toml", "reference.toml")  # the first one installed


def regime(ratio: float) -> str:
    """``"hydrodynamic"`` (Lambda > 3), ``"mixed"`` (1 <= Lambda <= 3) or ``"dry"`` (Lambda < 1)."""
    if ratio > HYDRODYNAMIC:
        return "hydrodynamic"
    return "mixed" if ratio >= MIXED else "dry"


def _last_revolution(result) -> dict[str, np.ndarray]:
    from weftsim.post.analysis import complete_revolutions

    return common.revolution_steps(result, max(complete_revolutions(result) - 1, 0))


def _cell(scene_name: str, models, overrides: dict, progress: bool, base: str | Path | None = None) -> dict:
    start = time.perf_counter()
    if base is None:
        scene = common.load(models, scene_name, overrides)
    else:  # weftsim study regime SCENE: the cells are that scene with the cell's keys
        from weftsim.input.scene import load_scene

        scene = load_scene(base, overrides)
    result = common.solve(scene, progress=progress)
    wall = time.perf_counter() - start
    steps = _last_revolution(result)
    joint = steps["contact_force_N"]
    out: dict[str, Any] = {"wall_time_per_revolution_s": wall / result.scene.drive.revolutions,
           "steps": int(result.solver_stats.get("steps", 0)), "contact_force_max_N": float(joint.max()),
           "driving_torque_max_Nm": float(np.abs(steps["driving_torque_Nm"]).max())}
    if "film_ratio" in steps:
        total = steps["film_force_N"] + steps["asperity_force_N"] + joint
        ratio = float(steps["film_ratio"].min())
        out |= {"film_ratio_min": ratio, "regime": regime(ratio),
                "film_force_max_N": float(steps["film_force_N"].max()),
                "asperity_force_max_N": float(steps["asperity_force_N"].max()), "joint_force_max_N": float(total.max())}
    return out


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the regime map into ``outdir``; returns what ``regime.json`` holds.

    ``scene``: the scene file or bundled name its cells run on (default: the bundled loom, else the reference).

    ``overrides``: scene keys (file units) applied to every run, except speed, clearance and viscosity
    (:data:`SETS`); e.g. ``joint_e.lubrication.roughness_um`` or ``joint_e.lubrication.model``.
    """
    from weftsim.post.output import write_csv, write_figure, write_json

    overrides = common.study_overrides("regime", SETS, revolutions, REVOLUTIONS, overrides)
    lubrication = {k: v for k, v in overrides.items() if k.startswith("joint_e.lubrication.")}
    dry_overrides = {k: v for k, v in overrides.items() if k not in lubrication}
    scene_name = next((name for name in SCENES if (Path(models) / name).is_file()), SCENES[-1])
    source = scene
    base_scene = common.base_scene(models, source, overrides) if source is not None else \
        common.load(models, scene_name, overrides)
    if source is not None:
        scene_name = base_scene.name  # names the scene in the report and the figure
    outdir = common.open_directory(outdir, force, base_scene)
    rows = []
    for rpm in SPEEDS_RPM:
        for c in CLEARANCES_MM:
            base = {**dry_overrides, "drive.speed_rpm": rpm, "joint_e.clearance_mm": c}
            dry = _cell(scene_name, models, {**base, "name": f"dry_{rpm:g}rpm_{c:g}mm"}, progress, source)
            for eta in VISCOSITIES_MPA_S:
                keys = {**base, **lubrication, "joint_e.lubrication.viscosity_mpa_s": eta,
                        "name": f"oil_{rpm:g}rpm_{c:g}mm_{eta:g}mPas"}
                oil = _cell(scene_name, models, keys, progress, source)
                rows.append({"speed_rpm": rpm, "clearance_mm": c, "viscosity_mpa_s": eta, **oil,
                             "dry_contact_force_max_N": dry["contact_force_max_N"],
                             "dry_driving_torque_max_Nm": dry["driving_torque_max_Nm"],
                             "dry_wall_time_per_revolution_s": dry["wall_time_per_revolution_s"]})
    written = {"csv": write_csv(outdir / "regime.csv", {key: [row[key] for row in rows] for key in rows[0]
                                                        if key != "regime"})}
    written["figure"] = write_figure(outdir / "study-regime.png", regime_figure(rows, scene_name))
    report = {"study": "regime", "scene": scene_name.removesuffix(".toml"), **common.record(base_scene, overrides),
              "revolutions": overrides["drive.revolutions"],
              "limits": {"hydrodynamic_above": HYDRODYNAMIC, "dry_below": MIXED}, "cells": rows,
              "files": sorted(p.name for p in written.values()) + ["regime.json"]}
    written["json"] = write_json(outdir / "regime.json", report)
    common.finish(outdir, written, "regime", base_scene)
    return report


def regime_figure(rows: list[dict], scene_name: str):
    """One column per viscosity: the minimum film ratio (colour: regime) and the peak joint force against
    the dry contact force, over clearance, one line per speed."""
    from weftsim.post.plots import pyplot

    plt = pyplot()
    etas = sorted({row["viscosity_mpa_s"] for row in rows})
    speeds = sorted({row["speed_rpm"] for row in rows})
    fig, axes = plt.subplots(2, len(etas), figsize=(4.2 * len(etas), 7.2), sharex=True, squeeze=False)
    colours = dict(zip(speeds, ("tab:blue", "tab:orange", "tab:red", "tab:green")))
    for k, eta in enumerate(etas):
        top, bottom = axes[0, k], axes[1, k]
        top.axhspan(FLOOR_DRAWN, MIXED, color="tab:red", alpha=0.08)
        top.axhspan(MIXED, HYDRODYNAMIC, color="tab:orange", alpha=0.1)
        top.axhspan(HYDRODYNAMIC, 1e4, color="tab:green", alpha=0.06)
        for rpm in speeds:
            cells = [r for r in rows if r["viscosity_mpa_s"] == eta and r["speed_rpm"] == rpm]
            c = [r["clearance_mm"] for r in cells]
            # Lambda = 0 (the film gone) is drawn at the bottom edge of the axis.
            top.plot(c, [max(r["film_ratio_min"], FLOOR_DRAWN) for r in cells], "o-", color=colours[rpm],
                     label=f"{rpm:g} rpm")
            bottom.plot(c, [r["joint_force_max_N"] for r in cells], "o-", color=colours[rpm], label=f"{rpm:g} rpm, oil")
            bottom.plot(c, [r["dry_contact_force_max_N"] for r in cells], "x--", color=colours[rpm], lw=0.8,
                        label=f"{rpm:g} rpm, dry")
        top.set_yscale("log")
        top.set_ylim(FLOOR_DRAWN, max(10.0, max(r["film_ratio_min"] for r in rows) * 1.5))
        top.set_title(f"viscosity {eta:g} mPa s")
        top.set_ylabel("minimum film ratio h_min / sigma")
        top.text(0.02, 0.04, "dry < 1 < mixed < 3 < hydrodynamic (film gone: bottom edge)", transform=top.transAxes,
                 fontsize=7)
        bottom.set_yscale("log")
        bottom.set_ylabel("peak joint force [N]")
        bottom.set_xlabel("radial clearance at E [mm]")
        bottom.set_xscale("log")
        clearances = sorted({row["clearance_mm"] for row in rows})
        bottom.set_xticks(clearances, [f"{c:g}" for c in clearances])
        bottom.minorticks_off()
        for ax in (top, bottom):
            ax.grid(alpha=0.3, which="both")
        top.legend(fontsize=7)
        bottom.legend(fontsize=6)
    fig.suptitle(f"regime map of the lubricated joint E ({scene_name.removesuffix('.toml')}, reference engine, "
                 "steady revolution)")
    fig.tight_layout()
    return fig


def format_report(report: dict) -> str:
    """The table ``weftsim study regime`` prints."""
    lines = [f"regime map at E, scene {report['scene']}, {report['revolutions']:g} revolutions (last one counted), "
             "reference engine",
             f"{'rpm':>5s} {'c mm':>6s} {'mPa s':>6s} {'min h/s':>8s} {'regime':>12s} {'F oil N':>10s} "
             f"{'F dry N':>10s} {'s/rev oil':>9s} {'s/rev dry':>9s}"]
    for r in report["cells"]:
        lines.append(f"{r['speed_rpm']:5.0f} {r['clearance_mm']:6.3g} {r['viscosity_mpa_s']:6.0f} "
                     f"{r['film_ratio_min']:8.3g} {r['regime']:>12s} {r['joint_force_max_N']:10.4g} "
                     f"{r['dry_contact_force_max_N']:10.4g} {r['wall_time_per_revolution_s']:9.3g} "
                     f"{r['dry_wall_time_per_revolution_s']:9.3g}")
    return "\n".join(lines)
