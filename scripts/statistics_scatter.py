"""How much the statistics that `weftsim compare` checks scatter within ONE engine (issue 11).

After the first impacts the impact sequence is chaotic (docs/hard-cases.md): any change far
below the model's accuracy (here the crank speed times 1 + k 1e-9, k = 0..M-1) gives another,
equally valid impact sequence.  The statistics over revolutions 2..N (RMS of rapier acceleration
and driving torque, mean contact force, 99th percentiles of the magnitudes) then scatter; two
engines that solve the same equations differ by the difference of two such draws.  This script
runs that ensemble on the reference engine's compiled path and prints, per scene, statistic and
window (revolutions 2..10 and 2..N), the relative standard deviation s and the largest
relative deviation from the ensemble mean.  The tolerances of tests/test_engine_agreement.py
are derived from this table (see the comment there).

    python scripts/statistics_scatter.py [--members 16] [--revolutions 40] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from weftsim.post.analysis import complete_revolutions, statistics
import weftsim


def solve(scene):
    """The reference engine through the one door (weftsim.simulate: before-run checks, solve, vetting)."""
    return weftsim.simulate(scene, "reference", on_warning=lambda text: None)

from weftsim.input.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("clearance_0p25mm_400rpm", "clearance_0p50mm_400rpm")
QUANTITIES = (("rapier_acceleration_m_s2", "rms"), ("driving_torque_Nm", "rms"), ("contact_force_N", "mean"),
              ("rapier_acceleration_m_s2", "p99_abs"), ("driving_torque_Nm", "p99_abs"),
              ("contact_force_N", "p99_abs"))  # fmt: skip


def truncated(result, revolutions: int):
    """The result cut to its first ``revolutions`` revolutions (steps only: statistics read steps)."""
    import dataclasses

    keep = result.steps["time_s"] <= revolutions * result.scene.drive.period + 1e-12
    steps = {name: values[keep] for name, values in result.steps.items()}
    return dataclasses.replace(result, steps=steps)


def ensemble(scene_name: str, members: int, revolutions: int, rtol: float) -> dict:
    path = ROOT / "models" / "paper" / f"{scene_name}.toml"
    base = load_scene(path).drive.speed
    windows = {10: [], revolutions: []}
    for k in range(members):
        rpm = base * 60.0 / (2.0 * np.pi) * (1.0 + k * 1e-9)
        scene = load_scene(path, {"drive.revolutions": revolutions, "drive.speed_rpm": rpm,
                                  "solver.reference.method": "numba_DOP853", "solver.reference.rtol": rtol,
                                  "solver.reference.atol": rtol * 1e-3})  # fmt: skip
        result = solve(scene)
        if not result.ok or complete_revolutions(result) < revolutions:
            raise RuntimeError(f"{scene_name} member {k}: {result.message}")
        for n in windows:
            stats = statistics(truncated(result, n))
            windows[n].append([stats[name][stat] for name, stat in QUANTITIES])
        print(f"  {scene_name} member {k + 1}/{members}", file=sys.stderr, flush=True)
    out = {}
    for n, rows in windows.items():
        values = np.array(rows)
        mean = values.mean(axis=0)
        out[f"2..{n}"] = {f"{name}:{stat}": {"mean": float(mean[i]),
                                              "rel_std": float(values[:, i].std(ddof=1) / abs(mean[i])),
                                              "rel_max_dev": float(np.abs(values[:, i] / mean[i] - 1.0).max())}
                          for i, (name, stat) in enumerate(QUANTITIES)}  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=16)
    parser.add_argument("--revolutions", type=int, default=40)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    table = {name: ensemble(name, args.members, args.revolutions, args.rtol) for name in SCENES}
    print(f"{'scene':26s} {'window':7s} {'quantity':36s} {'rel std':>8s} {'max dev':>8s}")
    for scene, windows in table.items():
        for window, rows in windows.items():
            for q, row in rows.items():
                print(f"{scene:26s} {window:7s} {q:36s} {row['rel_std']:8.4f} {row['rel_max_dev']:8.4f}")
    if args.json:
        Path(args.json).write_text(json.dumps(table, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
