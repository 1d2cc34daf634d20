"""The wear prediction on both engines side by side (docs/wear.md section 11).

For each engine, ``--runs`` predictions of SCENE until the effective clearance reaches ``--limit-mm``, the
j-th with the wear coefficient j units in the last place larger (the ensemble's chaos runs), printing the
hours at which each level of ``--levels-mm`` is reached and the CPU time of the prediction::

    PYTHONPATH=. python scripts/wear_engines.py loom --limit-mm 0.1 --levels-mm 0.05 0.1 --runs 3
    PYTHONPATH=. python scripts/wear_engines.py reference --limit-mm 0.3 --runs 6
    PYTHONPATH=. python scripts/wear_engines.py loom --limit-mm 0.1 --runs 1 --rtol 1e-8

``--rtol``: both engines' relative tolerance (and absolute tolerance 1e-3 of it) instead of their defaults.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from weftsim.input.scene import load_scene
from weftsim.wear.engines import ENGINES, simulator
from weftsim.wear.ensemble_design import last_bits
from weftsim.wear.extrapolate import MAX_HOURS, advance, effective_clearance, predict


def hours_to(scene, limit: float, levels: list[float], engine: str) -> tuple[list[float], int, float]:
    """(hours at each level, updates, CPU seconds) of one prediction of ``scene`` on ``engine`` up to ``limit`` (m)."""
    c0, latest = scene.joint.clearance, []

    def beyond() -> bool:
        return bool(latest) and effective_clearance(c0, *advance(latest[-1], scene)[2:]) >= limit

    cpu = time.process_time()
    updates = predict(scene, MAX_HOURS, on_update=lambda u: latest.__setitem__(slice(None), u), stop=beyond,
                      simulate=simulator(engine))  # fmt: skip
    cpu = time.process_time() - cpu
    hours = [u.hours for u in updates]
    clearance = [effective_clearance(c0, u.bearing, u.journal) for u in updates]
    end_hours, _, bearing, journal = advance(updates[-1], scene)
    hours.append(end_hours)
    clearance.append(effective_clearance(c0, bearing, journal))
    clearance = np.maximum.accumulate(clearance)
    return [float(np.interp(level, clearance, hours)) for level in levels], len(updates), cpu


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene")
    p.add_argument("--limit-mm", type=float, required=True)
    p.add_argument("--levels-mm", type=float, nargs="*", help="clearances to report (default: the limit)")
    p.add_argument("--runs", type=int, default=3, help="chaos runs per engine (k + 0, 1, ... ulps)")
    p.add_argument("--rtol", type=float, help="both engines' relative tolerance instead of their defaults")
    p.add_argument("--engines", nargs="*", default=list(ENGINES))
    args = p.parse_args()
    scene = load_scene(args.scene)
    if args.rtol is not None:
        r = args.rtol
        scene = replace(scene, reference_solver=replace(scene.reference_solver, rtol=r, atol=1e-3 * r),
                        exudyn_solver=replace(scene.exudyn_solver, relative_tolerance=r, absolute_tolerance=1e-3 * r))
    levels = [x * 1e-3 for x in (args.levels_mm or [args.limit_mm])]
    print("engine, run, " + ", ".join(f"hours to {1e3 * x:g} mm" for x in levels) + ", updates, CPU s", flush=True)
    for engine in args.engines:
        for j in range(args.runs):
            hours, updates, cpu = hours_to(last_bits(scene, j), args.limit_mm * 1e-3, levels, engine)
            print(f"{engine}, {j}, " + ", ".join(f"{h:.6g}" for h in hours) + f", {updates}, {cpu:.1f}", flush=True)


if __name__ == "__main__":
    main()
