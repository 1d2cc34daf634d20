"""Benchmark of the reference engine on a lubricated loom in the mixed regime (issue 26; docs/performance.md,
"The mixed regime"): CPU time per revolution of the loom at 600 rpm with an oil film against the dry loom of the
same clearance, and of one wear update, all in this process (ratios, not wall times: the machine is shared).

Cases: c = 0.02 mm at 10, 20 and 40 mPa s (film ratio down to 0.37, 1.6 and 4.05) and c = 0.1 mm at 80 mPa s,
``--revolutions`` each on the default path; each case runs ``--repeats`` times, interleaved, after one warm-up
run, and the medians are printed with the load average.  ``--update`` adds one wear update
(:func:`weftsim.wear.extrapolate.simulate_update`: 1 settling + 4 revolutions) of the loom at 10 mPa s and dry,
on the new geometry.

    python scripts/bench_lubricated_mixed.py [--repeats 3] [--revolutions 2] [--update]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np

import weftsim
from weftsim import load_scene

LOOM = Path(__file__).resolve().parents[1] / "models" / "loom.toml"
OIL = "joint_e.lubrication.viscosity_mpa_s"
CASES = {  # name: (overrides, the dry case it is compared with)
    "dry, c = 0.02 mm": ({}, None),
    "10 mPa s": ({OIL: 10.0}, "dry, c = 0.02 mm"),
    "20 mPa s": ({OIL: 20.0}, "dry, c = 0.02 mm"),
    "40 mPa s": ({OIL: 40.0}, "dry, c = 0.02 mm"),
    "dry, c = 0.1 mm": ({"joint_e.clearance_mm": 0.1}, None),
    "c = 0.1 mm, 80 mPa s": ({"joint_e.clearance_mm": 0.1, OIL: 80.0}, "dry, c = 0.1 mm"),
}


def cpu_of(run) -> tuple[float, object]:
    """(CPU seconds of this process, the result) of ``run()``."""
    start = time.process_time()
    out = run()
    return time.process_time() - start, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--revolutions", type=float, default=2.0)
    parser.add_argument("--update", action="store_true", help="also time one wear update (10 mPa s and dry)")
    args = parser.parse_args()
    scenes = {name: load_scene(LOOM, keys, revolutions=args.revolutions) for name, (keys, _) in CASES.items()}
    for scene in scenes.values():
        weftsim.simulate(scene, "reference", on_warning=lambda text: None)  # warm-up: numba's cache
    cpu: dict[str, list[float]] = {name: [] for name in scenes}
    stats = {}
    for _ in range(args.repeats):
        for name, scene in scenes.items():
            seconds, result = cpu_of(lambda: weftsim.simulate(scene, "reference", on_warning=lambda text: None))
            cpu[name].append(seconds)
            stats[name] = result.solver_stats
    print(f"load average {os.getloadavg()}")
    for name, (_, dry) in CASES.items():
        per_rev = statistics.median(cpu[name]) / args.revolutions
        ratio = "" if dry is None else f"  {statistics.median(cpu[name]) / statistics.median(cpu[dry]):.1f}x dry"
        s = stats[name]
        print(f"{name:22s} {s['steps'] / args.revolutions:8.0f} steps/rev ({s['rejected_steps']} rejected in all), "
              f"{s['function_evaluations'] / args.revolutions:8.0f} evaluations/rev, CPU {per_rev:.3f} s/rev{ratio}"
              f"  [{s['method']}]")
    if args.update:
        from weftsim.wear.extrapolate import simulate_update

        empty = np.zeros(0)
        for keys in ({OIL: 10.0}, {}):
            scene = load_scene(LOOM, keys)
            simulate_update(scene, empty, empty)
            times = [cpu_of(lambda: simulate_update(scene, empty, empty))[0] for _ in range(args.repeats)]
            print(f"wear update, {'10 mPa s' if keys else 'dry'}: CPU {statistics.median(times):.2f} s")


if __name__ == "__main__":
    main()
