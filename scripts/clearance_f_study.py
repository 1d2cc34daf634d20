"""What a clearance at F adds to the clearance at E (docs/clearance-f.md, issue 13 section 2).

The reference mechanism at 400 rpm with c = 0.25 mm at E only, at F only and at both (and the ideal
mechanism for scale), on the reference engine's compiled path at rtol 1e-8.  For each case: the first revolution's
maxima (the start-up impact, reproducible to ~1e-4 between engines) and the statistics over
revolutions 2..N (RMS and 99th percentile of |x| of rapier acceleration, driving torque and the
contact forces).  After the first impacts the impact sequence is chaotic (docs/physics.md section 6):
each case is run as a small ensemble whose crank speed differs by k x 1e-9 (k = 0..M-1), and the
table gives the ensemble mean and the largest deviation from it, so that a difference between cases
can be told from the scatter within one.

    python scripts/clearance_f_study.py [--revolutions 20] [--members 3] [--out docs]

Writes ``<out>/img/clearance-f.png`` (one revolution of each case) and ``<out>/data/clearance-f.json``
and prints the Markdown table of docs/clearance-f.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from weftsim.post.analysis import peaks, statistics
import weftsim


def solve(scene):
    """The reference engine through the one door (weftsim.simulate: before-run checks, solve, vetting)."""
    return weftsim.simulate(scene, "reference", on_warning=lambda text: None)

from weftsim.input.scene import load_scene
from weftsim.studies.common import revolution_steps

ROOT = Path(__file__).resolve().parents[1]
CASES = {"E only": (0.25, 0.0), "F only": (0.0, 0.25), "E and F": (0.25, 0.25), "ideal": (0.0, 0.0)}
# The reference engine at the tolerances of the engine-agreement tests (tests/test_engine_agreement.py):
# at the default rtol 1e-5 one of five 40-revolution members with c at F alone failed the energy guard
# (a 0.36 deg step through a lasting contact, whose dense output misses the balance by 9.8 J inside it).
SETTINGS = {"solver.reference.method": "numba_DOP853", "solver.reference.rtol": 1e-8, "solver.reference.atol": 1e-11}
QUANTITIES = (("rapier_acceleration_m_s2", "a [m/s²]", 1.0), ("driving_torque_Nm", "T [N·m]", 1.0),
              ("contact_force_N", "F_N at E [kN]", 1e-3), ("contact_force_f_N", "F_N at F [kN]", 1e-3))  # fmt: skip


def scene_of(case: str, revolutions: float, member: int):
    c_e, c_f = CASES[case]
    scene = load_scene(ROOT / "models" / "clearance_ef.toml", {
        "joint_e.clearance_mm": c_e, "joint_f.clearance_mm": c_f, "drive.revolutions": revolutions, **SETTINGS})
    drive = dataclasses.replace(scene.drive, speed=scene.drive.speed * (1.0 + member * 1e-9))
    return dataclasses.replace(scene, drive=drive)


def numbers(result) -> dict:
    """First-revolution maxima of |x| and statistics over revolutions 2..N of each quantity present."""
    first = peaks(result, 0)
    stats = statistics(result)
    out = {}
    for name, _, _ in QUANTITIES:
        if name not in result.steps or (name == "contact_force_N" and result.scene.joint.is_ideal):
            continue
        out[name] = {"first_max_abs": max(abs(first[name]["min"]), abs(first[name]["max"])) if name in first
                     else float(np.max(np.abs(result.steps[name])))}  # fmt: skip
        if stats is not None and name in stats:
            out[name].update({"rms": stats[name]["rms"], "p99_abs": stats[name]["p99_abs"]})
    return out


def ensemble(case: str, revolutions: float, members: int) -> dict:
    runs, wall, keep = [], [], None
    for k in range(members if case != "ideal" else 1):
        t0 = time.perf_counter()
        result = solve(scene_of(case, revolutions, k))
        wall.append(time.perf_counter() - t0)
        if not result.ok:
            raise SystemExit(f"{case}: {result.message}")
        runs.append(numbers(result))
        keep = keep or result
    summary = {}
    for name in runs[0]:
        summary[name] = {}
        for stat in runs[0][name]:
            values = np.array([r[name][stat] for r in runs])
            mean = float(values.mean())
            summary[name][stat] = {"mean": mean, "spread": float(np.max(np.abs(values - mean)) / abs(mean))
                                   if mean else 0.0}  # fmt: skip
    return {"numbers": summary, "wall_time_s": wall, "path": keep.path_text}, keep


def figure(results: dict, target: Path) -> None:
    """Revolution 2 of each case in four panels (weftsim.post.plots.channel_panels)."""
    from weftsim.post.output import write_figure
    from weftsim.post.plots import channel_panels

    styles = {"ideal": {"color": "k", "lw": 1.2, "ls": "--"}, "E only": {"color": "tab:blue"},
              "F only": {"color": "tab:orange"}, "E and F": {"color": "tab:green"}}  # fmt: skip
    curves = []
    for case, result in results.items():
        data = revolution_steps(result, 1)
        if result.scene.joint.is_ideal:  # no contact force at an ideal E
            data.pop("contact_force_N")
        curves.append((case, data, {"lw": 0.7} | styles[case]))
    title = "Reference mechanism, 400 rpm, c = 0.25 mm at E, at F, at both (revolution 2, reference engine)"
    write_figure(target, channel_panels(curves, title, QUANTITIES))


def table(data: dict) -> str:
    rows = ["| case | " + " | ".join(f"{label} first rev. max / RMS / p99" for _, label, _ in QUANTITIES) + " |",
            "|---|" + "---|" * len(QUANTITIES)]
    for case, block in data.items():
        cells = []
        for name, _, scale in QUANTITIES:
            n = block["numbers"].get(name)
            if n is None:
                cells.append("-")
                continue
            parts = [f"{n[s]['mean'] * scale:.4g}" + (f" ±{100 * n[s]['spread']:.1f}%" if n[s]["spread"] > 0 else "")
                     for s in ("first_max_abs", "rms", "p99_abs") if s in n]
            cells.append(" / ".join(parts))
        rows.append(f"| {case} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revolutions", type=float, default=20.0)
    parser.add_argument("--members", type=int, default=3)
    parser.add_argument("--out", type=Path, default=ROOT / "docs")
    args = parser.parse_args(argv)
    data, shown = {}, {}
    for case in CASES:
        data[case], shown[case] = ensemble(case, args.revolutions, args.members)
    for sub in ("data", "img"):
        (args.out / sub).mkdir(parents=True, exist_ok=True)
    (args.out / "data" / "clearance-f.json").write_text(json.dumps(
        {"revolutions": args.revolutions, "members": args.members, "cases": data}, indent=1) + "\n")
    figure(shown, args.out / "img" / "clearance-f.png")
    print(table(data))
    for case, block in data.items():
        print(f"{case}: {block['path']}; wall time per run {np.mean(block['wall_time_s']):.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
