"""The paper's parameter studies as weftsim sweeps, plus the dense map the paper could not afford.

    python scripts/paper_sweeps.py [--out out/paper-sweeps] [--jobs N] [--engine reference] [--only map]

Runs, on models/reference.toml (c = 0.25 mm, 400 rpm, variable_kd, 2 revolutions):

- ``clearance``: c = 0.01, 0.25, 0.50 mm at 400 rpm (paper Fig. 12);
- ``speed``: 300, 500, 800 rpm at c = 0.25 mm (paper Fig. 13);
- ``map``: c from 0.01 to 0.50 mm x speed from 300 to 800 rpm (every paper case lies on it),

each exactly as ``weftsim sweep`` would (the equivalent commands are printed), into
OUT/<study>/, and copies the map's figure to docs/img/sweep-clearance-speed.png.
Rerunning skips finished cells, so an interrupted run continues where it stopped.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from weftsim.input.scene import SceneError
from weftsim.sweep import SweepError, format_report, plan_sweep, run_sweep

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "reference.toml"
IMAGE = ROOT / "docs" / "img" / "sweep-clearance-speed.png"

# 0.01 mm (the paper's smallest) then every 0.05 mm to 0.50: 11 values holding 0.01, 0.25 and 0.50.
MAP_CLEARANCES = "0.01," + ",".join(f"{0.05 * k:.2f}" for k in range(1, 11))
STUDIES = {
    "clearance": (["clearance_mm=0.01,0.25,0.5"], []),
    "speed": (["speed_rpm=300,500,800"], []),
    # 11 x 11 = 121 cells of 10 revolutions (~35 s on 2 cores with the default compiled path, issue 12;
    # 2 revolutions before); speed every 50 rpm holds 300, 400, 500 and 800.
    "map": ([f"clearance_mm={MAP_CLEARANCES}", "speed_rpm=300:800:11"], ["revolutions=10"]),
}


def command(study: str, outdir: Path, engine: str) -> str:
    vary, fixed = STUDIES[study]
    flags = [f"--vary {v}" for v in vary] + [f"--set {f}" for f in fixed]
    return f"weftsim sweep models/reference.toml {' '.join(flags)} --engine {engine} -o {outdir}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/paper-sweeps", help="parent directory of the three sweeps")
    parser.add_argument("--jobs", type=int, default=None, help="local worker processes (default: all CPUs)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address instead of local processes")
    parser.add_argument("--engine", default="reference", help="reference (fast) or exudyn")
    parser.add_argument("--only", choices=sorted(STUDIES), action="append", help="run only these studies")
    parser.add_argument("--no-image", action="store_true", help="do not copy the map figure to docs/img/")
    args = parser.parse_args(argv)
    failed = 0
    for study in args.only or list(STUDIES):
        vary, fixed = STUDIES[study]
        outdir = Path(args.out) / study
        print(f"== {study}: {command(study, outdir, args.engine)}", flush=True)
        try:
            plan = plan_sweep(SCENE, vary, fixed, args.engine)
            report = run_sweep(plan, outdir, jobs=args.jobs, scheduler=args.scheduler)
        except (SweepError, SceneError) as exc:
            print(f"paper_sweeps {study}: error: {exc}", file=sys.stderr)
            return 2
        print(format_report(report), flush=True)
        failed += report.failed
        if study == "map" and report.figure and not args.no_image:
            shutil.copyfile(report.figure, IMAGE)
            print(f"  copied {report.figure} to {IMAGE.relative_to(ROOT)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
