"""The oiled loom's wear ensemble (docs/wear.md section 9, "Lubricated"): the numbers the docs quote.

    python scripts/lubricated_ensemble.py [OUTDIR] [--samples 1000]

Runs (or resumes) the ensemble of the docs' command in OUTDIR (default out/loom-oil-ensemble), then
re-samples the same design predictions without simulating: 4x the samples and another seed (the
sampling's convergence), and the one-ended (forward Euler) hours of the single `weftsim wear` runs
instead of the two-ended ones (the update interval's share of the error).  Prints one table.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

UNCERTAIN = {
    "joint_e.lubrication.viscosity_mpa_s": "walther(220,19,45,85)",
    "joint_e.wear.wear_coefficient": "lognormal(3.2e-7,0.7)",
    "joint_e.clearance_mm": "triangular(0.015,0.02,0.03)",
    "drive.speed_rpm": "uniform(500,700)",
}
SETTINGS = {"joint_e.lubrication.viscosity_mpa_s": 54.0,  # the nominal oil (65 C); the design overrides it
            "joint_e.wear.max_clearance_change": 0.1, "joint_e.wear.revolutions_per_update": 1}
DESIGN = {"joint_e.lubrication.viscosity_mpa_s": 5}
LIMIT, LEVEL = 0.1e-3, 0.05e-3


def _row(label: str, ens: dict, horizon: float) -> str:
    from weftsim.wear.censored import censored_quantile, text_hours

    cells = []
    for i in (ens["levels"].searchsorted(LEVEL - 1e-12), -1):
        h = ens["hours"][:, i]
        q = [text_hours(censored_quantile(h, p)[0], horizon) for p in (0.1, 0.5, 0.9)]
        r = h[np.isfinite(h)]
        q_r = [text_hours(censored_quantile(r, p)[0], horizon) for p in (0.1, 0.5, 0.9)] if r.size > 1 else ["-"] * 3
        cells.append(f"{100 * np.mean(np.isfinite(h)):.1f} % reach; p10/p50/p90 " + " / ".join(q)
                     + "; of those: " + " / ".join(q_r))
    return f"{label:<34} 0.05 mm: {cells[0]}  |  0.1 mm: {cells[1]}"


def main() -> None:
    from weftsim.input.scene import apply_overrides, load_scene
    from weftsim.wear.ensemble import combine, plan, wear_ensemble
    from weftsim.wear.jobs import CURVE
    from weftsim.wear.uncertain import parse_uncertain

    ap = argparse.ArgumentParser()
    ap.add_argument("outdir", nargs="?", default=str(ROOT / "out" / "loom-oil-ensemble"))
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--max-clearance-change", type=float, default=SETTINGS["joint_e.wear.max_clearance_change"])
    ap.add_argument("--resample-only", action="store_true", help="only resample the finished design predictions "
                    "in OUTDIR (e.g. those of the docs' weftsim command, whose scene differs from this script's "
                    "in the file keys it records, so that the script would not reuse them)")
    args = ap.parse_args()
    scene = apply_overrides(load_scene(ROOT / "models" / "loom.toml"),
                            {**SETTINGS, "joint_e.wear.max_clearance_change": args.max_clearance_change}, "script")
    if args.resample_only:
        data = json.loads((Path(args.outdir) / "ensemble.json").read_text())
    else:
        data = wear_ensemble(scene, UNCERTAIN, args.samples, LIMIT, args.outdir, jobs=args.jobs, levels=(LEVEL,),
                             chaos_runs=1, design_points=DESIGN, force=True, announce=print)
    horizon = data["horizon_hours"]
    parsed = [parse_uncertain(f"{k}={v}") for k, v in UNCERTAIN.items()]
    jobs, dynamic, nodes = plan(scene, parsed, 1, DESIGN)
    results = {n: json.loads((Path(args.outdir) / "jobs" / n / CURVE).read_text())["result"] for n, _ in jobs}
    euler = {n: {**r, "hours": r["hours_one_ended"]} for n, r in results.items()}
    print(f"design predictions: {len(jobs)}, simulation CPU {data.get('simulation_cpu_time_s') or math.nan:.0f} s, "
          f"wall {data['simulation_wall_time_s']:.0f} s; never: {len(data['never'])}, "
          f"censored: {len(data['censored_design_points'])}")
    for label, res, n, seed in (("1000 samples, seed 0", results, args.samples, 0),
                                ("1000 samples, seed 1", results, args.samples, 1),
                                ("4000 samples, seed 0", results, 4 * args.samples, 0),
                                ("16000 samples, seed 0", results, 16 * args.samples, 0),
                                ("1000 samples, one-ended hours", euler, args.samples, 0)):
        ens = combine(scene, parsed, dynamic, nodes, res, n, LIMIT, seed, (LEVEL,), horizon)
        print(_row(label, ens, horizon))
    shares = sorted(data["shares"].items(), key=lambda kv: -kv[1]["share"])
    print("shares of the spread (0.1 mm): " + ", ".join(f"{k} {100 * v['share']:.1f} % (rho {v['rank_correlation']:+.2f})"
                                                        for k, v in shares if math.isfinite(v["share"])))


if __name__ == "__main__":
    main()
