"""Command line: ``weftsim kinematics | run | compare | sweep | study``.  Thin: parse, call, report.

Every expected failure (bad scene, bad flag, unwritable output, failed solve) is one
line on stderr and a non-zero exit status; tracebacks only for real bugs.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

from weftsim.exitcodes import EXIT_DISAGREE, EXIT_FAILED, EXIT_USAGE  # noqa: F401 (re-exported)


class CliError(Exception):
    """An error to print as one line, with an exit status."""

    def __init__(self, message: str, status: int = EXIT_USAGE):
        super().__init__(message)
        self.status = status


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (the usage stays behind --help) and no abbreviated flags
    (``--speed 400`` must not silently mean ``--speed-rpm``)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message: str):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _positive(kind):
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
        return value

    return parse


def _non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def _add_scene_flags(p: argparse.ArgumentParser, full: bool = True) -> None:
    p.add_argument("scene", help="scene file (TOML), e.g. models/reference.toml")
    p.add_argument("-o", "--output", default=None, help="output directory (default: out/<scene name>)")
    p.add_argument("--force", action="store_true",
                   help="write into an output directory that holds files weftsim did not write")
    p.add_argument("--speed-rpm", type=_positive(float), help="override drive.speed_rpm")
    if full:
        p.add_argument("--clearance-mm", type=_non_negative, help="override joint_e.clearance_mm (0 = ideal joint)")
        p.add_argument("--law", help="override joint_e.law (contact force law)")
        p.add_argument("--revolutions", type=_positive(float), help="override drive.revolutions")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="weftsim",
        description="Weft insertion mechanism of a rapier loom with a clearance joint at E: "
        "Exudyn multibody model and closed-form Lagrange cross-check.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log what happens")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("kinematics", help="ideal rapier motion over one revolution (CSV + plot)")
    _add_scene_flags(p, full=False)

    p = sub.add_parser("run", help="simulate a scene with one engine (CSV, summary.json, figure)")
    _add_scene_flags(p)
    p.add_argument("--engine", default="exudyn", choices=("exudyn", "reference"),
                   help="exudyn (multibody model, default) or reference (closed-form Lagrange cross-check)")
    p.add_argument("--no-plot", action="store_true", help="skip the figure")

    p = sub.add_parser("compare", help="run both engines on one scene and compare them")
    _add_scene_flags(p)
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")

    p = sub.add_parser("sweep", help="run a grid of scene variants in parallel (table of peaks, plots)",
                       description="Run every combination of the --vary values on a pool of worker processes "
                       "(or a Dask cluster) into OUTPUT/<cell>/; rerunning skips finished cells.  See docs/sweeps.md.")
    p.add_argument("scene", help="base scene file (TOML), e.g. models/reference.toml")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=VALUES",
                   help="a scene key (clearance_mm, speed_rpm, law, ... or a dotted key) and its values: "
                   "a list 0.01,0.25,0.5 or an inclusive range start:stop:count; repeat for more axes")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="fixed override for every cell")
    p.add_argument("-o", "--output", default=None, help="sweep directory (default: out/<scene name>-sweep)")
    p.add_argument("--engine", default="exudyn",
                   help="exudyn (default), reference, or module:function of your own engine: a plug-in, "
                   "imported and run like any code (docs/sweeps.md)")
    p.add_argument("--allow-cwd-engine", action="store_true",
                   help="allow a --engine module:function found in the current directory (refused by default)")
    p.add_argument("--jobs", type=_positive(int), help="local worker processes (default: number of CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing Dask cluster, e.g. tcp://host:8786")
    p.add_argument("--cell-figures", action="store_true", help="also draw each cell's channels.png")
    p.add_argument("--yes", action="store_true", help="run a grid of more than 2000 cells (refused without it)")

    p = sub.add_parser("study", help="one of the paper's studies: figures, CSV and JSON (docs/paper-comparison.md)",
                       description="Run a study of the paper: contact-law (Fig. 7-9), clearance (Fig. 12), "
                       "speed (Fig. 13, with the acceleration spectrum), engines (Fig. 16), or all of them.")
    p.add_argument("name", help="contact-law, clearance, speed, engines or all")
    p.add_argument("-o", "--output", default=None,
                   help="output directory (default: out/study-NAME; with 'all': parent of one directory per study)")
    p.add_argument("--models", default="models", help="directory of the scene files (default: models)")
    p.add_argument("--revolutions", type=_positive(float), help="override the study's crank revolutions per run")
    p.add_argument("--force", action="store_true",
                   help="write into an output directory that holds files weftsim did not write")

    p = sub.add_parser("bench", help="work-precision benchmark of every engine setting (docs/performance.md)",
                       description="Time every engine setting on an easy and two hard scenes against a converged "
                       "solution: tables, log-log figures and JSON.  The full mode takes ~30 min on 2 cores.")
    p.add_argument("--quick", action="store_true", help="a few settings, 2 revolutions (a few minutes)")
    p.add_argument("-o", "--output", default=None, help="output directory (default: out/bench or out/bench-quick)")
    p.add_argument("--case", action="append", help="only this case (repeatable): c0.25mm-400rpm, c0.01mm-800rpm, "
                   "c0.50mm-800rpm")
    p.add_argument("--models", default="models", help="directory of the scene files (default: models)")
    p.add_argument("--repeats", type=_positive(int), default=5, help="timed runs per setting (median; default 5)")
    p.add_argument("--force", action="store_true",
                   help="write into an output directory that holds files weftsim did not write")
    return parser


def _overrides(args) -> dict:
    return {
        "drive.speed_rpm": getattr(args, "speed_rpm", None),
        "joint_e.clearance_mm": getattr(args, "clearance_mm", None),
        "joint_e.law": getattr(args, "law", None),
        "drive.revolutions": getattr(args, "revolutions", None),
    }


def _load(args):
    from weftsim.scene import load_scene

    return load_scene(args.scene, _overrides(args))


def _outdir(args, scene, suffix: str = "") -> Path:
    return Path(args.output) if args.output else Path("out") / (scene.name + suffix)


def cmd_kinematics(args) -> int:
    import numpy as np

    from weftsim.kinematics import linkage_state
    from weftsim.output import finish_directory, prepare_directory, write_csv, write_figure
    from weftsim.plots import plot_kinematics

    scene = _load(args)
    outdir = prepare_directory(_outdir(args, scene, "-kinematics"), args.force)
    step = scene.output.sample_angle
    theta = np.linspace(0.0, 2.0 * math.pi, int(round(2.0 * math.pi / step)) + 1)
    state = linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    w = scene.drive.speed
    columns = {
        "crank_angle_deg": np.degrees(theta),
        "rapier_displacement_m": state.rapier_displacement,
        "rapier_velocity_m_s": w * state.d_rapier_displacement,
        "rapier_acceleration_m_s2": w * w * state.dd_rapier_displacement,
        "rocker_angle_deg": np.degrees(state.phi),
        "rocker_arm_angle_deg": np.degrees(state.theta_oe),
        "sector_angle_deg": np.degrees(state.theta_fg),
        "rod_angle_deg": np.degrees(state.theta_ef),
        "transmission_angle_deg": np.degrees(state.transmission_angle),
    }
    csv = write_csv(outdir / "kinematics.csv", columns)
    rpm = scene.drive.speed * 30 / math.pi
    fig = plot_kinematics(columns["crank_angle_deg"], columns["rapier_displacement_m"],
                          columns["rapier_velocity_m_s"], columns["rapier_acceleration_m_s2"],
                          f"{scene.name}: ideal rapier motion at {rpm:g} rpm")
    png = write_figure(outdir / "kinematics.png", fig)
    finish_directory(outdir, {"csv": csv, "png": png}, {"kind": "kinematics", "scene": scene.name})
    s, v, a = columns["rapier_displacement_m"], columns["rapier_velocity_m_s"], columns["rapier_acceleration_m_s2"]
    print(f"scene {scene.name}: {rpm:g} rpm, ideal joints")
    print(f"  stroke        {s.max() - s.min():.6f} m at {columns['crank_angle_deg'][s.argmax()]:.1f} deg")
    print(f"  velocity      {v.min():+.3f} .. {v.max():+.3f} m/s")
    print(f"  acceleration  {a.min():+.2f} .. {a.max():+.2f} m/s^2 (on the {math.degrees(step):g} deg grid)")
    ta = columns["transmission_angle_deg"]
    print(f"  transmission angle at F {ta.min():.2f} .. {ta.max():.2f} deg")
    print(f"wrote {csv} and {png}")
    return 0


def _solve(scene, engine: str, label: str | None = None):
    from weftsim.progress import Progress

    if engine == "reference":
        from weftsim.reference import solve
    elif engine == "exudyn":
        from weftsim.exudyn_engine import solve
    else:
        raise CliError(f"--engine must be 'reference' or 'exudyn', got {engine!r}")
    if label is None:  # a run's first line: the model and method it takes, and why
        from importlib import import_module

        select = import_module("weftsim.reference" if engine == "reference" else "weftsim.exudyn_engine").select_path
        path = select(scene)
        print(f"scene {scene.name}, engine {engine}: {path['model']}, {path['method']} ({path['reason']})", flush=True)
    progress = Progress(label or f"{engine} {scene.name}")
    try:
        return solve(scene, progress=progress)
    finally:
        progress.close()


def _report_run(result, written) -> None:
    from weftsim.analysis import complete_revolutions, peaks

    print(f"scene {result.scene.name}, engine {result.engine}: {result.status} "
          f"in {result.wall_time_s:.2f} s wall time")
    n = complete_revolutions(result)
    if n:
        p = peaks(result, n - 1)
        print(f"  peaks over revolution {n}:")
        for name, v in p.items():
            print(f"    {name:28s} {v['min']:+.6g} .. {v['max']:+.6g}")
    if result.first_contact_angle_deg is not None:
        print(f"  first contact at crank angle {result.first_contact_angle_deg:.3f} deg")
    for kind, path in written.items():
        print(f"  wrote {path}")


def cmd_run(args) -> int:
    from weftsim.output import prepare_directory, write_run
    from weftsim.plausibility import report_lines

    scene = _load(args)
    outdir = prepare_directory(_outdir(args, scene), args.force)
    result = _solve(scene, args.engine)
    written = write_run(result, outdir, figure=not args.no_plot, force=args.force)
    _report_run(result, written)
    report_lines(result, "run")
    if not result.ok:
        raise CliError(f"simulation failed: {result.message} (results up to the failure written to {outdir}, "
                       "marked incomplete in summary.json)", EXIT_FAILED)
    return 0


def cmd_compare(args) -> int:
    from weftsim.compare import run_compare

    scene = _load(args)
    return run_compare(scene, _outdir(args, scene, "-compare"), as_json=args.json, solve=_solve, force=args.force)


class _SweepTerminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP during a sweep: handled as Ctrl-C is (queued cells cancelled, workers ended,
    table rewritten, lock released), then reported with the signal's own exit status."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _raise_terminated(signum, frame):
    raise _SweepTerminated(signum)


def cmd_sweep(args) -> int:
    import signal

    from weftsim.sweep import SweepError, format_report, plan_sweep, run_sweep

    handled = (signal.SIGTERM, signal.SIGHUP)
    previous = {sig: signal.signal(sig, _raise_terminated) for sig in handled}
    try:
        plan = plan_sweep(args.scene, args.vary, args.set, args.engine, allow_large=args.yes,
                          allow_cwd_engine=args.allow_cwd_engine,
                          announce=lambda line: print(line, file=sys.stderr, flush=True))
        outdir = Path(args.output) if args.output else Path("out") / (Path(args.scene).stem + "-sweep")
        report = run_sweep(plan, outdir, jobs=args.jobs, scheduler=args.scheduler, cell_figures=args.cell_figures)
    except SweepError as exc:
        raise CliError(str(exc)) from None
    except _SweepTerminated as exc:
        name = signal.Signals(exc.signum).name
        raise CliError(f"terminated by {name}; finished cells are kept, run the same command again to resume",
                       128 + exc.signum) from None
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    print(format_report(report))
    if report.failed:
        raise CliError(f"{report.failed} of {report.total} cells failed (see {report.table} and each failed cell's "
                       "error.txt)", EXIT_FAILED)
    return 0


def cmd_study(args) -> int:
    from weftsim.studies import STUDIES, SimulationFailed, StudyError, format_study, run_study

    names = list(STUDIES) if args.name == "all" else [args.name]
    for name in names:
        outdir = Path(args.output) / name if args.output and args.name == "all" else args.output
        try:
            report = run_study(name, outdir, args.models, args.revolutions, args.force)
        except SimulationFailed as exc:
            raise CliError(str(exc), EXIT_FAILED) from None
        except StudyError as exc:
            raise CliError(str(exc)) from None
        print(format_study(name, report))
    return 0


def cmd_bench(args) -> int:
    from weftsim.bench import CASES, run_benchmark

    unknown = [c for c in args.case or [] if c not in CASES]
    if unknown:
        raise CliError(f"unknown --case {', '.join(unknown)}; choose from {', '.join(CASES)}")
    outdir = args.output or ("out/bench-quick" if args.quick else "out/bench")
    report = run_benchmark(outdir, args.models, args.quick, args.case, repeats=args.repeats, force=args.force)
    print(f"benchmark done in {report['total_time_s']:.0f} s; wrote " + ", ".join(map(str, report["files"])))
    return 0


COMMANDS = {"kinematics": cmd_kinematics, "run": cmd_run, "compare": cmd_compare, "sweep": cmd_sweep,
            "study": cmd_study, "bench": cmd_bench}


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(name)s: %(message)s")
    from weftsim.output import OutputError
    from weftsim.scene import SceneError

    try:
        return COMMANDS[args.command](args)
    except (SceneError, OutputError) as exc:
        print(f"weftsim {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except CliError as exc:
        print(f"weftsim {args.command}: error: {exc}", file=sys.stderr)
        return exc.status
    except KeyboardInterrupt:
        print(f"weftsim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
