"""Regenerate the regression table of peaks, tests/regression/peaks.json, after an intended physics change.

    python scripts/regenerate_regression.py                 # every case (~3-5 minutes on 2 cores)
    python scripts/regenerate_regression.py --case NAME ...  # only these cases, the others kept
    python scripts/regenerate_regression.py --list           # the cases

Each case (weftsim.studies.regression.CASES) is run once for its values and once per
perturbation of its engine (round-off and error-control level: reference rtol x (1 +
1e-7) and rtol / 10; exudyn numba callback route and Newton tolerance / 10); each
quantity's tolerance is a safety factor times its largest measured shift, with a floor.
Commit the new table with the change that caused it and say why in the message.
tests/test_regression.py recomputes every case and fails outside the tolerances.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from weftsim.post.output import to_json, write_text
from weftsim.studies import regression

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "tests" / "regression" / "peaks.json"
COMMAND = "python scripts/regenerate_regression.py"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", action="append", help="regenerate only this case (repeatable)")
    parser.add_argument("--list", action="store_true", help="list the cases and exit")
    parser.add_argument("-o", "--output", default=str(TABLE), help=f"table file (default: {TABLE.relative_to(ROOT)})")
    args = parser.parse_args(argv)
    if args.list:
        for case in regression.CASES:
            print(f"{case.name:34s} {case.engine:9s} {case.kind:16s} {case.scene} {case.overrides}")
        return 0
    names = {case.name for case in regression.CASES}
    unknown = sorted(set(args.case or ()) - names)
    if unknown:
        print(f"unknown case(s) {unknown}; see --list", file=sys.stderr)
        return 2
    target = Path(args.output)
    old = {}
    if args.case and target.exists():
        old = {entry["case"]: entry for entry in json.loads(target.read_text())["entries"]}
    start = time.perf_counter()
    entries = []
    for case in regression.CASES:
        if args.case and case.name not in args.case:
            if case.name in old:
                entries.append(old[case.name])
            continue
        print(f"{case.name} ({case.engine}, {case.kind})", flush=True)
        entries.append(regression.build_entry(case, ROOT, log=lambda text: print(text, flush=True)))
    table = {
        "description": "Peaks of reproducible quantities (docs/physics.md section 6) for tests/test_regression.py; "
                       "see weftsim/studies/regression.py for the cases and the tolerance rule.",
        "command": COMMAND + "".join(f" --case {name}" for name in args.case or ()),
        "environment": regression.environment(),
        "rules": regression.rules(),
        "entries": entries,
    }
    target.parent.mkdir(parents=True, exist_ok=True)
    write_text(target, to_json(table))
    print(f"wrote {target} ({len(entries)} cases) in {time.perf_counter() - start:.0f} s")
    for entry in entries:
        print(f"  {entry['case']:34s} {entry['wall_time_s']:6.1f} s{'  (slow)' if entry['slow'] else ''}")
        for name, q in entry["quantities"].items():
            tol = f"rtol {q['rtol']:.2g}" if "rtol" in q else f"atol {q['atol']:.2g} deg"
            print(f"    {name:34s} {q['value']:+.10g}  {tol}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
