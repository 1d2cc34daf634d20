"""The wear study of docs/wear.md: the reference loom (models/reference.toml, c0 = 0.25 mm at E) run
until the effective clearance passes 0.5 mm, at several crank speeds and update criteria.

Prints (and writes with --json) the hours for the clearance to grow from 0.25 to 0.5 mm at each
speed and update fraction f (and at twice the revolutions per update), the power law fitted to
hours against speed, and draws docs/img/wear_profile.png (worn profiles at 400 rpm),
docs/img/wear_growth.png (clearance and response against hours at 400 and 800 rpm) and
docs/img/wear_speed.png (hours to 0.5 mm against speed).  ~10 min on 2 cores.

    python scripts/wear_study.py [--json out.json] [--no-figures]
"""

from __future__ import annotations

import argparse
import dataclasses as dc
import json
import time
from pathlib import Path

import numpy as np

from weftsim.post.output import write_figure
from weftsim.input.scene import load_scene
from weftsim.wear.extrapolate import advance, effective_clearance, limit_hours, predict
from weftsim.wear.figures import growth_figure, profile_figure, statistic_label
from weftsim.wear.store import table

ROOT = Path(__file__).resolve().parents[1]
LIMIT = 0.5e-3  # m
SPEEDS = (300.0, 400.0, 500.0, 600.0, 800.0)


def until_limit(rpm: float, fraction: float, revolutions: int | None = None):
    """Updates of a prediction run until the clearance passes LIMIT (plus the state after the last)."""
    scene = load_scene(ROOT / "models" / "reference.toml", {"drive.speed_rpm": rpm})
    wear = dc.replace(scene.joint.wear, max_clearance_change=fraction,
                      revolutions_per_update=revolutions or scene.joint.wear.revolutions_per_update)
    scene = dc.replace(scene, joint=dc.replace(scene.joint, wear=wear))
    last = []

    def stop() -> bool:
        return effective_clearance(scene.joint.clearance, *advance(last[0], scene)[2:]) > LIMIT

    wall = time.perf_counter()
    updates = predict(scene, 1e6, on_update=lambda done: last.__setitem__(slice(None), [done[-1]]), stop=stop)
    wall = time.perf_counter() - wall
    hours, revolutions, bearing, journal = advance(updates[-1], scene)
    updates.append(dc.replace(updates[-1], hours=hours, revolutions=revolutions, bearing=bearing, journal=journal,
                              step_revolutions=0.0))
    return scene, updates, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", help="write the numbers to this file")
    parser.add_argument("--no-figures", action="store_true")
    args = parser.parse_args()
    rows, kept = [], {}
    for rpm in SPEEDS:
        cases = [(0.02, None), (0.01, None)] if rpm in (400.0, 800.0) else [(0.02, None)]
        if rpm == 400.0:
            cases.append((0.02, 16))
        for fraction, revolutions in cases:
            scene, updates, wall = until_limit(rpm, fraction, revolutions)
            hours = limit_hours(updates, scene.joint.clearance, LIMIT)
            row = {"speed_rpm": rpm, "max_clearance_change": fraction,
                   "revolutions_per_update": scene.joint.wear.revolutions_per_update, "hours_0p25_to_0p5mm": hours,
                   "revolutions_to_0p5mm": hours * rpm * 60.0, "updates": len(updates) - 1, "wall_s": wall}
            rows.append(row)
            print(json.dumps(row), flush=True)
            if fraction == 0.02 and revolutions is None:
                kept[rpm] = (scene, updates)
    base = {r["speed_rpm"]: r["hours_0p25_to_0p5mm"] for r in rows
            if r["max_clearance_change"] == 0.02 and r["revolutions_per_update"] == 4}
    speeds = np.array(sorted(base))
    exponent = float(np.polyfit(np.log(speeds), np.log([base[s] for s in speeds]), 1)[0])
    print(f"hours to 0.5 mm ~ speed^{exponent:.2f}")
    response = {}
    for rpm, (scene, updates) in kept.items():
        columns = table(scene, updates[:-1])  # the last entry is the extrapolated end state, not simulated
        response[rpm] = {name: [float(values[0]), float(values[-1])] for name, values in columns.items()}
        print(f"{rpm:g} rpm, first and last simulated update: " + ", ".join(
            f"{name} {v[0]:.4g} -> {v[1]:.4g}" for name, v in response[rpm].items()
            if name.endswith(("_N", "_m_s2", "_Nm", "clearance_mm"))))
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "hours_speed_exponent": exponent, "response": response},
                                              indent=1) + "\n")
    if args.no_figures:
        return
    img = ROOT / "docs" / "img"
    scene, updates = kept[400.0]
    write_figure(img / "wear_profile.png", profile_figure(scene, updates, "reference loom, 400 rpm: wear at E"))
    columns = {rpm: table(*kept[rpm]) for rpm in (400.0, 800.0)}
    fig = growth_figure(columns[400.0], "reference loom: 400 rpm (dots), 800 rpm (crosses)")
    for ax, name in zip(fig.axes, ("effective_clearance_e_mm", "contact_force_e_p99_N", "rapier_acceleration_p99_m_s2",
                                   "driving_torque_p99_Nm")):
        ax.plot(columns[800.0]["hours"], columns[800.0][name], "x-", ms=3, label="800 rpm " + statistic_label(name))
        ax.legend(fontsize=7)
    write_figure(img / "wear_growth.png", fig)
    from weftsim.post.plots import figure

    fig = figure(figsize=(6, 4))
    ax = fig.add_subplot(1, 1, 1)
    ax.loglog(speeds, [base[s] for s in speeds], "o-", label="hours, 0.25 -> 0.5 mm")
    ax.loglog(speeds, base[400.0] * (speeds / 400.0) ** exponent, "--", label=f"fit: speed^{exponent:.2f}")
    ax.set_xlabel("crank speed [rpm]")
    ax.set_ylabel("operating hours")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    ax.set_title("reference loom, k = 1e-7, H = 2 GPa: hours to double the clearance at E", fontsize=9)
    fig.tight_layout()
    write_figure(img / "wear_speed.png", fig)


if __name__ == "__main__":
    main()
