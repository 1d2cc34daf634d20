"""Measure the clearance-force callback routes of the Exudyn engine on the loom model.

Usage::

    python scripts/bench_callbacks.py [--revolutions 0.25] [--repeat 3] [--profile]

Runs the reference scene (c = 0.25 mm, 400 rpm, default solver settings) for part of a
revolution once per route and repeat, and prints the median cost per step, callback calls
per step (counted on the python route), the cost per call measured outside Exudyn, the
ideal-joint model as the floor, and the agreement of the routes' peak contact force.
``--profile`` adds Exudyn's own timer breakdown for the default route.  Times are CPU times
(``time.process_time``); on a shared machine they still vary by +-20 %: compare routes
within one run.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import time

import exudyn as exu
import numpy as np

from weftsim.joint.contact import make_law
from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.clearance_joint import DEFAULT_ROUTE, ROUTES
from weftsim.exudyn_engine.mechanism import build_mechanism
from weftsim.exudyn_engine.sensors import add_sensors, step_channels
from weftsim.exudyn_engine.solver import simulation_settings, step_plan
from weftsim.input.params import Drive, Scene


def run(scene: Scene, route: str | None, count: bool = False, profile: bool = False):
    """One simulation; returns (CPU s per step, calls per step or None, peak F_N, Newton it/step)."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    counter = [0] if count else None
    model = build_mechanism(mbs, scene, callback=route, call_counter=counter)
    sensors = add_sensors(mbs, model)
    mbs.Assemble()
    if model.clearance is not None:
        model.clearance.reset(mbs)
    _, n = step_plan(scene)
    settings = simulation_settings(scene, n)
    settings.show.computationTime = profile  # fills the timers (and prints a summary)
    solver = exu.MainSolverImplicitSecondOrder()
    t0 = time.process_time()  # CPU time: less disturbed by other processes than wall time
    solver.SolveSystem(mbs, settings)
    wall = time.process_time() - t0
    ch = step_channels(mbs, model, sensors)
    if profile:
        _print_timers(solver.timer, n)
    calls = counter[0] / n if count else None
    return wall / n, calls, float(np.max(ch["contact_force_N"])), solver.it.newtonStepsCount / n


_TIMERS = ("ODE2RHS", "reactionForces", "AERHS", "newtonIncrement", "massMatrix", "totalJacobian",
           "factorization", "python", "writeSolution", "integrationFormula", "postNewton", "overhead")


def _print_timers(timer, n_steps: int) -> None:
    """Exudyn's own timers (s) per step and as shares of the measured total."""
    total = timer.total
    print(f"Exudyn timers, default route: total {1e6 * total / n_steps:.1f} us/step")
    for name in _TIMERS:
        value = getattr(timer, name)
        print(f"  {name:18s} {1e6 * value / n_steps:7.2f} us/step  {100 * value / total:5.1f} %")


def per_call_cost(law, clearance: float, v_min: float, repeat: int = 200_000) -> dict[str, float]:
    """Seconds per direct call of the python and numba callbacks at a contact state."""
    out = {}
    u, v, k = [clearance * 1.001, 0.0, 0.0], [0.01, 0.0, 0.0], [0.1, -1e-6, 0.05]
    for name, f in (("python", callbacks.make_python_force(law, clearance, v_min)),
                    ("numba", callbacks.make_numba_force(law, clearance, v_min))):  # fmt: skip
        t0 = time.perf_counter()
        for _ in range(repeat):
            f(None, 0.0, 0, u, v, k, None, None)
        out[name] = (time.perf_counter() - t0) / repeat
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revolutions", type=float, default=0.25)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    scene = Scene(drive=Drive(revolutions=args.revolutions))
    ideal = dataclasses.replace(scene, joint=dataclasses.replace(scene.joint, clearance=0.0))
    h, n = step_plan(scene)
    print(f"scene: c = {scene.joint.clearance * 1e3} mm, {scene.drive.speed * 30 / math.pi:.0f} rpm, "
          f"{args.revolutions} rev, h = {h:.4g} s, {n} steps, law {scene.joint.law}")  # fmt: skip
    law = make_law(scene.joint)
    cost = per_call_cost(law, scene.joint.clearance, scene.joint.min_impact_velocity)
    print("direct call cost: " + ", ".join(f"{k} {1e6 * v:.2f} us" for k, v in cost.items()))
    rows = {}
    for rep in range(args.repeat):
        for route in ROUTES + ("ideal",):
            if route == "ideal":
                per_step, calls, peak, its = run(ideal, None)
            else:
                per_step, calls, peak, its = run(scene, route, count=(route == "python"))
            rows.setdefault(route, []).append((per_step, calls, peak, its))
    print(f"{'route':10s} {'us/step (median)':>17s} {'all runs':>24s} {'calls/step':>11s} "
          f"{'Newton it/step':>15s} {'peak F_N [N]':>16s}")  # fmt: skip
    for route, vals in rows.items():
        times = [1e6 * v[0] for v in vals]
        calls = vals[0][1]
        print(f"{route:10s} {statistics.median(times):17.1f} {' '.join(f'{t:.1f}' for t in times):>24s} "
              f"{'' if calls is None else f'{calls:.2f}':>11s} {vals[0][3]:15.2f} {vals[0][2]:16.6f}")  # fmt: skip
    print(f"default route ('auto'): {DEFAULT_ROUTE}")
    if args.profile:
        run(scene, DEFAULT_ROUTE, profile=True)


if __name__ == "__main__":
    main()
