"""Frequency study of contact-force outliers on the reference engine (issue 11).

    python scripts/contact_outliers.py [--jobs 1] [--only speed_500] [--methods numba_DOP853]
        [--set joint_e.impact_velocity_rule=onset] [--csv docs/data/contact-outliers.csv]
        [--section contact-outliers] [--force] [--report-only]

Runs every scene of models/paper/ for 10 revolutions with scipy DOP853 at rtol 1e-6..1e-10 and
numba_DOP853 at rtol 1e-4..1e-10 (atol = rtol * 1e-3): 72 runs.  Each finished run is added to
the CSV at once; a rerun skips the runs already there (``--force`` redoes them), so an
interrupted study continues where it stopped.  The table goes to docs/hard-cases.md between
the markers of ``--section``.

``--flores`` runs the flores ce = 0.3 case instead (models/reference.toml with law flores,
restitution 0.3, each impact-velocity rule, numba_DOP853 and DOP853 at rtol 1e-9, 10 revolutions;
``--methods numba_DOP853,DOP853,exudyn`` adds the Exudyn engine at the scene's settings, for the agreement of the peaks;
weftsim.studies.outliers.flores_cells) into docs/data/contact-outliers-flores.csv and the
section ``contact-outliers-flores``.  Measures: weftsim/studies/outliers.py.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from weftsim.input.scene import SceneError
from weftsim.studies.common import StudyError
from weftsim.studies import outliers, outliers_report
from weftsim.sweep.grid import SweepError, parse_set

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", default=str(ROOT / "models"), help="models directory (holds paper/)")
    parser.add_argument("--only", nargs="+", help="scenes whose name contains one of these")
    parser.add_argument("--methods", help=f"comma-separated subset of {','.join(outliers.STUDY_RTOLS)}")
    parser.add_argument("--revolutions", type=float, default=outliers.STUDY_REVOLUTIONS)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="scene override, every run")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes, 1 or 2")
    parser.add_argument("--flores", action="store_true", help="the flores ce = 0.3 case instead of the study")
    parser.add_argument("--csv", help="default docs/data/contact-outliers.csv (--flores: contact-outliers-flores.csv)")
    parser.add_argument("--doc", default=str(ROOT / "docs" / "hard-cases.md"))
    parser.add_argument("--section", help="marker name in --doc (default contact-outliers, --flores: "
                        "contact-outliers-flores); '' = no table")  # fmt: skip
    parser.add_argument("--force", action="store_true", help="rerun the selected runs already in the CSV")
    parser.add_argument("--report-only", action="store_true", help="only rewrite the table from the CSV")
    args = parser.parse_args(argv)
    name = "contact-outliers-flores" if args.flores else "contact-outliers"
    csv_path = args.csv or str(ROOT / "docs" / "data" / f"{name}.csv")
    section = name if args.section is None else args.section
    try:
        if not args.revolutions > 1:
            raise StudyError(f"--revolutions must be > 1 (revolution 1 is left out of the median), "
                             f"got {args.revolutions}")
        overrides = tuple(parse_set(text) for text in args.set)
        methods = args.methods.split(",") if args.methods else None
        if args.flores:
            cells = outliers.flores_cells(args.models, methods or ("numba_DOP853", "DOP853"),
                                          revolutions=args.revolutions, overrides=overrides)  # fmt: skip
        else:
            cells = outliers.study_cells(args.models, methods, args.only, args.revolutions, overrides)
        for cell in cells[:1]:
            cell.scene()  # a bad --set fails here, in one line, before any run
        if not args.report_only:
            outliers.run_study(cells, csv_path, args.jobs, args.force)
        if section:
            rows = outliers.read_rows(csv_path)
            command = "python scripts/contact_outliers.py " + shlex.join(
                [a for a in argv if a not in ("--force", "--report-only")])
            report = outliers_report.flores_report if args.flores else outliers_report.markdown_report
            outliers_report.replace_section(args.doc, section, report(rows, command.strip()))
    except (StudyError, SceneError, SweepError) as exc:
        print(f"contact_outliers: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
