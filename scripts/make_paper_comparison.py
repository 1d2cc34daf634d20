"""Run the paper's four studies and write docs/paper-comparison.md with their figures.

    python scripts/make_paper_comparison.py            # all studies (~5-10 minutes on 2 cores), then the report
    python scripts/make_paper_comparison.py --reuse    # the report from the studies' JSON already in --out

Each study runs exactly as ``weftsim study NAME -o OUT/NAME`` (and prints the same
lines); its ``study-*.png`` figures are copied to docs/img/ and the report is rendered
from the studies' JSON by weftsim.studies.report.render: no number is typed in.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

from weftsim.post.output import write_text
from weftsim.studies import STUDIES, format_study, run_study
from weftsim.studies.regression import environment
from weftsim.studies.report import render

ROOT = Path(__file__).resolve().parents[1]
REPORT = ROOT / "docs" / "paper-comparison.md"
IMAGES = ROOT / "docs" / "img"
JSON_NAME = {"contact-law": "contact-law.json", "clearance": "clearance.json", "speed": "speed.json",
             "engines": "engines.json"}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/paper-comparison", help="parent directory of the study outputs")
    parser.add_argument("--models", default=str(ROOT / "models"), help="scene directory")
    parser.add_argument("--reuse", action="store_true", help="do not run the studies; read their JSON from --out")
    parser.add_argument("--only", choices=list(STUDIES), action="append",
                        help="run only these studies, reuse the others' JSON")
    parser.add_argument("--report", default=str(REPORT), help="Markdown file to write")
    args = parser.parse_args(argv)
    out = Path(args.out)
    reports, commands = {}, {}
    timing_file = out / "timings.json"  # wall time of each study's last run, kept for --reuse
    timings = json.loads(timing_file.read_text()) if timing_file.exists() else {}
    for name in STUDIES:
        outdir = out / name
        commands[name] = f"weftsim study {name} -o {outdir.as_posix()}"
        if args.reuse or (args.only and name not in args.only):
            path = outdir / JSON_NAME[name]
            if not path.exists():
                print(f"{path} is missing: run without --reuse first", file=sys.stderr)
                return 2
            reports[name] = json.loads(path.read_text())
            timings.setdefault(name, None)
        else:
            print(f"== {commands[name]}", flush=True)
            start = time.perf_counter()
            reports[name] = run_study(name, outdir, args.models, force=True)
            timings[name] = time.perf_counter() - start
            print(format_study(name, reports[name]), flush=True)
            print(f"({timings[name]:.0f} s)", flush=True)
            write_text(timing_file, json.dumps(timings, indent=2) + "\n")
        for figure in sorted(outdir.glob("study-*.png")):
            shutil.copyfile(figure, IMAGES / figure.name)
    commands["report"] = "python scripts/make_paper_comparison.py" + (" --reuse" if args.reuse else "")
    text = render(reports, timings, commands, environment())
    write_text(Path(args.report), text)
    print(f"wrote {args.report} and the figures in {IMAGES.relative_to(ROOT)}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
