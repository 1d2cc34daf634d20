"""Benchmark of issue 14's target: a 10,000-hour wear prediction of the reference loom at 400 rpm,
with the update interval converged to 1 % in the final clearance, in under 2 minutes (2 cores).

With the default wear coefficient (k = 1e-7) the clearance at E passes the journal radius long before
10,000 h (0.25 -> 0.5 mm takes ~50 h, docs/wear.md), so the benchmark runs at k = 1e-9: the same
simulations per update, a clearance that stays in the model's range over the 10,000 h.  Each update
criterion f (the largest clearance growth per update) runs ``--repeats`` times in this process; the
script prints the median wall time and the final clearance of each f, and the change of the final
clearance when f is halved (the convergence the target asks for: <= 1 %).

    python scripts/bench_wear.py [--repeats 3] [--fractions 0.04 0.02 0.01]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from weftsim.input.scene import load_scene
from weftsim.wear.extrapolate import effective_clearance, predict

ROOT = Path(__file__).resolve().parents[1]
HOURS = 10_000.0
WEAR_COEFFICIENT = 1e-9


def one_prediction(fraction: float) -> tuple[float, float, int]:
    """(wall time s, final effective clearance m, updates) of one 10,000-h prediction at 400 rpm."""
    scene = load_scene(ROOT / "models" / "reference.toml", {
        "drive.speed_rpm": 400.0, "joint_e.wear.wear_coefficient": WEAR_COEFFICIENT,
        "joint_e.wear.max_clearance_change": fraction,
    })  # fmt: skip
    start = time.perf_counter()
    updates = predict(scene, HOURS)
    wall = time.perf_counter() - start
    last = updates[-1]
    return wall, effective_clearance(scene.joint.clearance, last.bearing, last.journal), len(updates)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--fractions", type=float, nargs="+", default=[0.04, 0.02, 0.01])
    args = parser.parse_args()
    one_prediction(0.5)  # compile the kernels once, outside the timings
    finals = {}
    print(f"10,000 h at 400 rpm, k = {WEAR_COEFFICIENT:g}, medians of {args.repeats} runs")
    print(f"{'f':>6s} {'wall [s]':>9s} {'final c [mm]':>13s} {'updates':>8s} {'change on halving f':>20s}")
    for fraction in args.fractions:
        runs = [one_prediction(fraction) for _ in range(args.repeats)]
        wall = statistics.median(r[0] for r in runs)
        final = statistics.median(r[1] for r in runs)
        finals[fraction] = final
        coarser = finals.get(2.0 * fraction)
        change = "" if coarser is None else f"{(final - coarser) / coarser:+.2%}"
        print(f"{fraction:6.3f} {wall:9.1f} {final * 1e3:13.4f} {runs[0][2]:8d} {change:>20s}")


if __name__ == "__main__":
    main()
