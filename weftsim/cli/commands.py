"""Command line: ``weftsim scenes | kinematics | run | animate | compare | sweep | optimize | study | bench | wear |
bearing``.  Thin: parse,
call the Python interface (:mod:`weftsim.api`), report.

One grammar for the scene of every command: ``SCENE`` is a file or the name of a bundled scene,
``--set KEY=VALUE`` (repeatable) overrides any scene key, and ``--revolutions``, ``--speed-rpm``,
``--clearance-mm`` and ``--law`` are its shorthands (:func:`add_scene_flags`, :func:`scene_from_args`;
a new subcommand calls both, and :func:`add_output_flags` / :func:`output_directory` for ``-o``).  A
run's results go to ``out/<scene>/<engine>/``, so runs of the two engines do not overwrite each other.
A mistyped flag, command or key gets the closest spelling.

Every expected failure (bad scene, bad flag, unwritable output, failed solve) is a
:class:`weftsim.errors.WeftsimError`, printed as one line on stderr with its exit status;
tracebacks only for real bugs.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import math
import os
import signal
import sys
import threading
from pathlib import Path

from weftsim.api import ENGINE_NAMES as ENGINE_CHOICES
from weftsim.cli.grammar import (  # noqa: F401 (CliError, add_scene_flags, scene_from_args: for subcommands)
    SCENE_HELP,
    CliError,
    Parser,
    VersionAction,
    add_output_flags,
    add_scene_flags,
    command_overrides,
    models_directory,
    output_directory,
    overrides_tag,
    positive,
    scene_from_args,
    set_overrides,
    shorthand_values,
)
from weftsim.errors import WeftsimError
from weftsim.post.record import set_command
from weftsim.cli.signals import Terminated, terminated_as_interrupt  # noqa: F401 (Terminated: for subcommands)
from weftsim.errors import EXIT_DISAGREE, EXIT_FAILED, EXIT_USAGE  # noqa: F401 (re-exported)
from weftsim.cli.startup import EXIT_INTERRUPTED  # 128 + SIGINT, defined once for start-up and the commands

EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE: the reader of stdout went away (`| head`), as for any Unix tool


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``weftsim`` parser; with ``only`` (a command's name) the flags of optimize, wear and bearing, whose help
    imports their packages (~0.1 s of a ``weftsim run``), are added only if ``only`` is that command."""
    parser = Parser(
        prog="weftsim",
        description="Weft insertion mechanism of a rapier loom with a clearance joint at E: "
        "Exudyn multibody model and closed-form Lagrange cross-check.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log what happens")
    parser.add_argument("--version", action=VersionAction,
                        help="the versions of weftsim and the packages it runs on, and exit")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    sub.add_parser("scenes", help="list the bundled scenes (name and description)")

    p = sub.add_parser("kinematics", help="ideal rapier motion over one revolution (CSV + plot)")
    add_scene_flags(p, shorthands=("speed_rpm",))  # ideal joints, one revolution: the others mean nothing here
    add_output_flags(p, "out/<scene name>/kinematics")

    p = sub.add_parser("run", help="simulate a scene with one engine (CSV, NPZ, summary.json, figure)")
    add_scene_flags(p)
    add_output_flags(p, "out/<scene name>/<engine>")
    p.add_argument("--engine", default="auto", choices=ENGINE_CHOICES,
                   help="exudyn (multibody model), reference (closed-form Lagrange cross-check) or auto "
                   "(the default engine, exudyn)")
    p.add_argument("--no-plot", action="store_true", help="skip the figure")

    p = sub.add_parser("animate", help="animation of the linkage, the journal and the rapier over a revolution (GIF)",
                       description="Simulate a scene and draw its last complete revolution: the linkage projected "
                       "on the four-bar plane, the journal in its clearance (magnified, labelled) and the rapier.")
    add_scene_flags(p)
    p.add_argument("-o", "--output", default=None,
                   help="animation file, .gif (or .mp4 with ffmpeg) (default: out/<scene name>/<engine>/animation.gif)")
    p.add_argument("--engine", default="auto", choices=ENGINE_CHOICES, help="as for run")
    p.add_argument("--frames", type=positive(int), default=72, help="frames over the revolution (default 72)")
    p.add_argument("--force", action="store_true",
                   help="write the animation into a directory that holds the results of another scene")
    p.add_argument("--viewer", action="store_true",
                   help="instead of the GIF, replay the run in Exudyn's own viewer (needs a display): the rigid-body "
                   "model is solved over the scene's revolutions, its coordinates stored in a solution file "
                   "(-o, default out/<scene name>/exudyn/viewer-solution.txt)")

    p = sub.add_parser("compare", help="run both engines on one scene and compare them")
    add_scene_flags(p)
    add_output_flags(p, "out/<scene name>/compare")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")

    p = sub.add_parser("sweep", help="run a grid of scene variants in parallel (table of peaks, plots)",
                       description="Run every combination of the --vary values on a pool of worker processes "
                       "(or a Dask cluster) into OUTPUT/<cell>/; rerunning skips finished cells.  See docs/sweeps.md.")
    p.add_argument("scene", help="base " + SCENE_HELP)
    p.add_argument("--vary", action="append", required=True, metavar="KEY=VALUES",
                   help="a scene key (clearance_mm, speed_rpm, law, ... or a dotted key) and its values: "
                   "a list 0.01,0.25,0.5 or an inclusive range start:stop:count; repeat for more axes")
    add_scene_flags(p, positional=False)
    p.add_argument("-o", "--output", default=None,
                   help="sweep directory (default: out/<scene name>/sweep-<engine>)")
    p.add_argument("--engine", default="auto",
                   help="auto (the default engine, exudyn), exudyn, reference, or module:function of your own "
                   "engine: a plug-in, imported and run like any code (docs/sweeps.md)")
    p.add_argument("--allow-cwd-engine", action="store_true",
                   help="allow a --engine module:function found in the current directory (refused by default)")
    p.add_argument("--jobs", type=positive(int), help="local worker processes (default: number of CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing Dask cluster, e.g. tcp://host:8786")
    p.add_argument("--cell-figures", action="store_true", help="also draw each cell's channels.png")
    p.add_argument("--yes", action="store_true", help="run a grid of more than 2000 cells (refused without it)")

    p = sub.add_parser("optimize", help=OPTIMIZE_HELP,
                       description="Differential evolution over the --vary keys (scipy), each design's runs on the "
                       "sweep's pool (or a Dask cluster), resumable: rerunning the same command continues.  "
                       "See docs/optimize.md.")
    if only in (None, "optimize"):
        _add_optimize_flags(p)

    p = sub.add_parser("study", help="one of the paper's studies: figures, CSV and JSON (docs/paper-comparison.md)",
                       description="Run a study of the paper: contact-law (Fig. 7-9), clearance (Fig. 12), "
                       "speed (Fig. 13, with the acceleration spectrum), engines (Fig. 16), regime (the lubricated "
                       "joint's film ratio and peak force over speed x clearance x viscosity), exchange (the weft exchange's "
                       "overlap, relative speed and head errors over clearance x speed, docs/rapier-tape.md), or all "
                       "of them.  "
                       "Each study sets its own scenes; --set and the shorthands apply to every run of it, "
                       "except what the study sets itself (the clearance of 'clearance', the speed of 'speed', "
                       "the speed and clearance of 'contact-law': refused).  With SCENE each case runs on that "
                       "scene (e.g. 'weftsim study clearance loom': the loom at c = 0 (ideal), 0.01, 0.25, 0.50 mm).")
    p.add_argument("name", help="contact-law, clearance, speed, engines, regime, exchange or all")
    p.add_argument("scene", nargs="?", default=None,
                   help="the scene to run the study's cases on: a scene file (TOML) or the name of a bundled scene "
                   "(default: the paper's reference scene and its cases in models/paper)")
    p.add_argument("-o", "--output", default=None,
                   help="output directory (default: out/study-NAME, with SCENE out/<scene name>/study-NAME; with "
                   "'all': parent of one directory per study)")
    p.add_argument("--models", default=None,
                   help="directory of the scene files (default: the bundled scenes, 'weftsim scenes')")
    add_scene_flags(p, positional=False)
    p.add_argument("--force", action="store_true",
                   help="write into an output directory that holds files weftsim did not write")

    p = sub.add_parser("wear", help=WEAR_HELP)
    if only in (None, "wear"):
        _add_wear_flags(p)

    p = sub.add_parser("bearing", help="steady plain-bearing check of an oiled joint: film, friction, temperature, "
                       "Stribeck curve (docs/lubricated-joint.md)")
    if only in (None, "bearing"):
        _add_bearing_flags(p)

    p = sub.add_parser("bench", help="work-precision benchmark of every engine setting (docs/performance.md)",
                       description="Time every engine setting on an easy and two hard scenes against a converged "
                       "solution: tables, log-log figures and JSON.  The full mode takes ~30 min on 2 cores.  "
                       "The cases fix their scenes, so it takes no scene flags.")
    p.add_argument("--quick", action="store_true", help="a few settings, 2 revolutions (a few minutes)")
    p.add_argument("--targets", action="store_true",
                   help="the speed targets of the default paths against the 0.1 defaults (about 4 min on an idle 2-core machine)")
    p.add_argument("-o", "--output", default=None,
                   help="output directory (default: out/bench, out/bench-quick or out/bench-targets)")
    p.add_argument("--case", action="append", help="only this case (repeatable): c0.25mm-400rpm, c0.01mm-800rpm, "
                   "c0.50mm-800rpm")
    p.add_argument("--models", default=None,
                   help="directory of the scene files (default: the bundled scenes, 'weftsim scenes')")
    p.add_argument("--repeats", type=positive(int), default=5, help="timed runs per setting (median; default 5)")
    p.add_argument("--force", action="store_true",
                   help="write into an output directory that holds files weftsim did not write")
    return parser


# What `weftsim wear` does, in the command list of `weftsim --help` (tests/test_hostile_words.py checks it names
# both joints and the ensemble, as the command does).
WEAR_HELP = ("predict the wear of the clearance joints (E, F, or both) over operating hours, or with --uncertain "
             "the hours to a clearance limit as a distribution (docs/wear.md)")


OPTIMIZE_HELP = ("find the design keys that minimise one or two objectives (peak joint force of a worn joint, ...) "
                 "under the loom's constraints (docs/optimize.md)")


def _add_optimize_flags(p: argparse.ArgumentParser) -> None:
    from weftsim.cli.optimize import add_flags

    add_flags(p, positive, add_scene_flags)


def _fixed_overrides(args: argparse.Namespace) -> list[str]:
    """The --set overrides and the shorthand flags as KEY=VALUE texts, fixed for every design or cell; a key given
    twice is refused first."""
    from weftsim.api import SCENE_FLAGS, scene_overrides

    scene_overrides(set_overrides(args), where="command line", **shorthand_values(args))  # a key given twice
    return list(args.set) + [f"{SCENE_FLAGS[flag]}={value!r}" if isinstance(value, float) else
                             f"{SCENE_FLAGS[flag]}={value}" for flag, value in shorthand_values(args).items()]


def cmd_optimize(args: argparse.Namespace) -> int:
    from weftsim.cli.optimize import run

    return run(args, _fixed_overrides(args))


def _add_wear_flags(p: argparse.ArgumentParser) -> None:
    from weftsim.cli.wear import add_flags

    add_scene_flags(p, shorthands=("speed_rpm", "clearance_mm", "law"))  # revolutions: set per update in [joint_e.wear]
    add_output_flags(p, "out/<scene name>/wear, wear-exudyn on --engine exudyn, wear-ensemble with --uncertain")
    add_flags(p, positive)


def _add_bearing_flags(p: argparse.ArgumentParser) -> None:
    from weftsim.cli.bearing import add_flags

    add_scene_flags(p, shorthands=("speed_rpm", "clearance_mm"))
    add_output_flags(p, "out/<scene name>/bearing")
    add_flags(p)


def cmd_bearing(args: argparse.Namespace) -> int:
    from weftsim.cli.bearing import run

    scene = scene_from_args(args)
    return run(args, scene, output_directory(args, scene, "bearing"))


def cmd_wear(args: argparse.Namespace) -> int:
    from weftsim.cli.wear import run

    scene = scene_from_args(args)
    # engines' states apart, and an ensemble apart from a prediction (each would replace the other's results)
    where = "wear-ensemble" if args.uncertain else "wear" if args.engine == "reference" else f"wear-{args.engine}"
    return run(args, scene, output_directory(args, scene, where), _stop_on_interrupt)


def _check_fits(scene, outdir: Path, runs: int = 1) -> None:
    """Refuse a run whose output grid cannot be held or written (before anything is created)."""
    from weftsim.post.output import check_output_fits, output_rows
    from weftsim.post.results import scene_channels

    what = (f"output.sample_deg = {math.degrees(scene.output.sample_angle):g} over "
            f"drive.revolutions = {scene.drive.revolutions:g}")
    columns = len(scene_channels(scene))
    check_output_fits(output_rows(scene), columns, outdir, what, runs)


def _announce_run_time(scene, engines: tuple[str, ...], command: str) -> None:
    """One line on stderr with the estimated run time of a long run (a warning above LONG_RUN_S), and for
    ``weftsim run`` one with the estimated size of the per-step record above LARGE_FILE_BYTES."""
    from weftsim.engines import get as engine_named
    from weftsim.post.output import _size
    from weftsim.checks.progress import LARGE_FILE_BYTES, LONG_RUN_S, SHOW_ESTIMATE_S, format_duration

    costs = [engine_named(engine).estimate(scene) for engine in engines]
    estimate = sum(cost.run_time_s for cost in costs)
    if estimate >= SHOW_ESTIMATE_S:
        prefix = "warning: " if estimate > LONG_RUN_S else ""
        print(f"weftsim {command}: {prefix}estimated run time ~{format_duration(estimate)} for "
              f"{scene.drive.revolutions:g} revolutions (within a factor of ~3); Ctrl-C stops it and keeps what was "
              "computed", file=sys.stderr, flush=True)
    size = max(cost.step_bytes for cost in costs) if command == "run" else 0.0
    if size > LARGE_FILE_BYTES:
        why = f"{scene.drive.revolutions:g} revolutions of solver steps"
        if any(cost.stiff_explicit for cost in costs):
            why = ("an explicit solver steps at ~1e-9 s on the friction or film of the joint (the reference engine's "
                   "solver.reference.method = 'auto' integrates it implicitly)")
        print(f"weftsim {command}: warning: the per-step record will be ~{_size(size)} (held in memory, written "
              f"compressed to result.npz): {why}; fewer drive.revolutions make it smaller", file=sys.stderr,
              flush=True)
    csv = _csv_bytes(scene) * len(engines)
    if command in ("run", "compare") and csv + size > LARGE_OUTPUT_BYTES:
        print(f"weftsim {command}: warning: the results will be ~{_size(csv + size)} on disk (~{_size(csv)} of "
              f"channels.csv: output.sample_deg = {math.degrees(scene.output.sample_angle):g} over "
              f"{scene.drive.revolutions:g} revolutions); writing them takes a while after the run (each file is "
              "announced); a coarser output.sample_deg or fewer drive.revolutions make them smaller",
              file=sys.stderr, flush=True)


# Results above this size are announced before the run, and each file as it is written (a 1000-revolution
# run of the loom wrote 160 MB of CSV and 418 MB of NPZ in 98 s after its progress had reached 100 %).
LARGE_OUTPUT_BYTES = 50e6


def _csv_bytes(scene) -> float:
    """Estimated bytes of one run's channels.csv (rows x columns x characters a value)."""
    from weftsim.post.output import CSV_BYTES_PER_VALUE, output_rows
    from weftsim.post.results import scene_channels

    return output_rows(scene) * len(scene_channels(scene)) * CSV_BYTES_PER_VALUE


def _writing_announcer(scene, engines: tuple[str, ...], command: str):
    """For results above LARGE_OUTPUT_BYTES, a callback saying on stderr which file is being written; else None."""
    from weftsim.engines import get as engine_named

    size = _csv_bytes(scene) + max(engine_named(engine).estimate(scene).step_bytes for engine in engines)
    if size <= LARGE_OUTPUT_BYTES:
        return None
    return lambda path: print(f"weftsim {command}: writing {path} ...", file=sys.stderr, flush=True)


# Signals that stop a run gracefully: the engine ends at its next step and what it computed is
# written.  SIGINT is Ctrl-C; SIGTERM is what `kill`, a batch scheduler at its time limit or a
# container stop sends first.
STOP_SIGNALS = {signal.SIGINT: "Ctrl-C, SIGINT", signal.SIGTERM: "SIGTERM"}


@contextlib.contextmanager
def _stop_on_interrupt(command: str):
    """While the block runs, SIGINT (Ctrl-C) or SIGTERM asks the running engine to stop at its next
    step and keep what it computed (weftsim.checks.guards.request_stop); a second signal abandons at once.

    Yields a dict whose ``"signal"`` is the signal number once one came (else None).
    """
    from weftsim.checks.guards import clear_stop, request_stop

    state = {"signal": None}
    previous = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}

    def handler(signum, frame):
        state["signal"] = signum
        request_stop(f"stopped by the user ({STOP_SIGNALS[signum]})")
        for other in STOP_SIGNALS:  # the next one ends the process at once
            signal.signal(other, signal.default_int_handler if other == signal.SIGINT else signal.SIG_DFL)
        if sys.stderr.isatty():  # at a terminal, say at once that the key was seen
            sys.stderr.write(f"\nweftsim {command}: stopping at the next step, keeping what was computed "
                             "(Ctrl-C again to abandon it)\n")

    clear_stop()
    if threading.current_thread() is not threading.main_thread():  # only the main thread may set handlers
        previous = {}
    for signum in previous:
        signal.signal(signum, handler)
    try:
        yield state
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old)
        clear_stop()


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send everything written to file descriptor 1 (Python's or a C library's, e.g. Exudyn's notes
    on import and its solver banners) to stderr while the block runs, so stdout holds only what is
    printed after it (``--json``)."""
    import ctypes

    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None).fflush(None)  # C stdio buffers still holding library output
        os.dup2(saved, 1)
        os.close(saved)


# The columns of kinematics.csv, in order (their number sizes the output before it is computed).
def cmd_kinematics(args: argparse.Namespace) -> int:
    from weftsim.api import KINEMATICS_COLUMNS, kinematics
    from weftsim.post.output import check_output_fits, prepare_directory, write_csv, write_figure, write_files
    from weftsim.post.plots import plot_kinematics

    scene = scene_from_args(args)
    step = scene.output.sample_angle
    rows = int(round(2.0 * math.pi / step)) + 1
    outdir = output_directory(args, scene, "kinematics")
    check_output_fits(rows, len(KINEMATICS_COLUMNS), outdir,
                      f"output.sample_deg = {math.degrees(step):g} over one revolution",
                      fix="a coarser output.sample_deg (any value up to 0.5 deg)")
    outdir = prepare_directory(outdir, args.force, scene, kind="kinematics")
    columns = kinematics(scene)
    rpm = scene.drive.speed * 30 / math.pi
    title = f"{scene.name}: ideal rapier motion at {rpm:g} rpm"
    written = write_files(outdir, {"kind": "kinematics", "scene": scene.name}, {
        "csv": ("kinematics.csv", lambda target: write_csv(target, columns)),
        "png": ("kinematics.png", lambda target: write_figure(target, plot_kinematics(
            columns["crank_angle_deg"], columns["rapier_displacement_m"], columns["rapier_velocity_m_s"],
            columns["rapier_acceleration_m_s2"], title, columns["transmission_angle_deg"]))),
    }, scene=scene)
    csv, png = written["csv"], written["png"]
    s, v, a = columns["rapier_displacement_m"], columns["rapier_velocity_m_s"], columns["rapier_acceleration_m_s2"]
    print(f"scene {scene.name}: {rpm:g} rpm, ideal joints")
    print(f"  stroke        {s.max() - s.min():.6f} m at {columns['crank_angle_deg'][s.argmax()]:.1f} deg")
    print(f"  velocity      {v.min():+.3f} .. {v.max():+.3f} m/s")
    print(f"  acceleration  {a.min():+.2f} .. {a.max():+.2f} m/s^2 (on the {math.degrees(step):g} deg grid)")
    ta = columns["transmission_angle_deg"]
    print(f"  transmission angle at F {ta.min():.2f} .. {ta.max():.2f} deg")
    print(f"wrote {csv} and {png}")
    return 0


def _solve(scene, engine: str, label: str | None = None, announce: bool = False):
    """:func:`weftsim.api.simulate` with progress on stderr; ``announce``: first the path it takes."""
    from weftsim.api import resolve_engine, select_path, simulate
    from weftsim.checks.progress import Progress

    engine = resolve_engine(engine, scene)
    if announce:  # `run`: its first line is the model and method it takes, and why
        path = select_path(scene, engine)
        print(f"scene {scene.name}, engine {engine}: {path['model']}, {path['method']} ({path['reason']})", flush=True)
        if "rapier" in path:  # a scene with a [rapier_tape]: whether the rigid rapier serves (docs/rapier-tape.md)
            print(f"rapier: {path['rapier']}", flush=True)
    progress = Progress(label or f"{engine} {scene.name}")
    try:  # the before-run checks are printed once by the command (_announce_checks)
        return simulate(scene, engine, progress=progress, on_warning=_quiet)
    finally:
        progress.close()


def _quiet(text: str) -> None:
    """Drop a before-run warning that the command has printed already."""


def _announce_checks(scene, command: str) -> None:
    """One ``warning:`` line on stderr per before-run plausibility check that fails (weftsim.checks.design_checks)."""
    from weftsim.checks.design_checks import before_run_lines

    for line in before_run_lines(scene):
        print(f"weftsim {command}: {line}", file=sys.stderr, flush=True)


def _report_run(result, written) -> None:
    from weftsim.post.analysis import complete_revolutions, peaks

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


def _interrupted_line(result, outdir: Path, signum: int) -> str:
    from weftsim.checks.guards import where

    t = float(result.steps["time_s"][-1]) if result.steps["time_s"].size else 0.0
    return (f"stopped by {STOP_SIGNALS[signal.Signals(signum)]} at {where(t, result.scene.drive.speed)}: the results up to "
            f"there are in {outdir} (summary.json says complete: false); rerun to compute the whole run")


def cmd_run(args: argparse.Namespace) -> int:
    from weftsim.api import resolve_engine
    from weftsim.post.output import prepare_directory, write_run
    from weftsim.checks.design_checks import report_lines

    scene = scene_from_args(args)
    engine = resolve_engine(args.engine, scene)  # a flexible tape: the reference engine
    outdir = output_directory(args, scene, engine)
    _check_fits(scene, outdir)
    # Checked before the estimate, which may still refuse the run (the engine's settings); created after it, so a
    # refused run leaves no directory behind.
    prepare_directory(outdir, args.force, scene, kind="run", create=False)
    with _stop_on_interrupt("run") as stop:  # from here a Ctrl-C stops the run (the estimate imports the engine)
        _announce_run_time(scene, (engine,), "run")
        outdir = prepare_directory(outdir, args.force, scene, kind="run")
        _announce_checks(scene, "run")
        result = _solve(scene, engine, announce=True)
    written = write_run(result, outdir, figure=not args.no_plot, force=args.force, npz=True,
                        on_write=_writing_announcer(scene, (engine,), "run"))
    _report_run(result, written)
    report_lines(result, "run")
    if stop["signal"] is not None and not result.ok:
        raise CliError(_interrupted_line(result, outdir, stop["signal"]), 128 + stop["signal"])
    if not result.ok:
        raise CliError(f"simulation failed: {result.message} (results up to the failure written to {outdir}, "
                       "marked incomplete in summary.json)", EXIT_FAILED)
    return 0


def cmd_animate(args: argparse.Namespace) -> int:
    from weftsim.post.animate import animated_window, check_format, check_frames, write_animation
    from weftsim.api import resolve_engine
    from weftsim.post.output import check_file_target
    from weftsim.post.record import check_same_scene, scene_toml

    scene = scene_from_args(args)
    engine = resolve_engine(args.engine, scene)  # a flexible tape: the reference engine
    if args.viewer:
        return _replay_in_viewer(args, scene, engine)
    target = Path(args.output) if args.output else output_directory(args, scene, engine) / "animation.gif"
    try:
        check_format(target)
        check_frames(args.frames)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    check_file_target(target)  # before the solve: a path that cannot be written fails now, not after it
    _check_fits(scene, target.parent)
    check_same_scene(target.parent, scene, args.force)  # beside the results of another scene: refused
    with _stop_on_interrupt("animate"):
        _announce_run_time(scene, (engine,), "animate")
        result = _solve(scene, engine, announce=True)
    if not result.ok:
        raise CliError(f"simulation failed: {result.message}; nothing animated", EXIT_FAILED)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        # The file records its own scene and command: -o may put it where no manifest is written.
        frames = write_animation(result, target, frames=args.frames, comment=scene_toml(scene))
    except OSError as exc:
        raise CliError(f"cannot write {target}: {exc.strerror or exc}") from None
    from weftsim.post.animate import clearance_magnification, joint_caption

    closure = float(abs(frames.rod_length - scene.geometry.l_ef).max())
    scale = clearance_magnification(max(frames.clearance, frames.clearance_f), scene.geometry.l_ef)
    t0, t1 = animated_window(result)  # the last whole revolution, or the run when shorter
    turn = math.degrees(scene.drive.speed * (t1 - t0))
    window = f"revolution {round(t0 / scene.drive.period) + 1}" if turn > 359.999 else "the run"
    print(f"wrote {target}: {args.frames} frames of {window}, crank angles 0.0..{turn * (1 - 1 / args.frames):.1f} "
          f"deg (each the solver step nearest), {joint_caption(frames, scale)}; "
          f"drawn rod EF within {closure:.1e} m of L_EF = {scene.geometry.l_ef:g} m")
    return 0


def _replay_in_viewer(args: argparse.Namespace, scene, engine: str) -> int:
    """``animate --viewer``: solve the rigid-body Exudyn model into a solution file, then replay it in
    Exudyn's viewer (:mod:`weftsim.exudyn_engine.viewer`); refused at once where no window can open."""
    if engine != "exudyn":
        raise CliError(f"--viewer replays an Exudyn run; drop --engine {engine} (or use --engine exudyn)")
    from weftsim.exudyn_engine.viewer import display_problem, period_label, record_solution, show_solution

    problem = display_problem()
    if problem is not None:
        raise CliError(problem)
    target = Path(args.output) if args.output else output_directory(args, scene, "exudyn") / "viewer-solution.txt"
    from weftsim.post.output import check_file_target

    check_file_target(target)
    _check_fits(scene, target.parent)
    print(f"scene {scene.name}: solving the Exudyn rigid-body model for the viewer ({period_label(scene)})",
          flush=True)
    try:
        with _stdout_to_stderr():  # Exudyn's banners
            recording = record_solution(scene, target)
    except OSError as exc:
        raise CliError(f"cannot write {target}: {exc.strerror or exc}") from None
    print(f"wrote {target}: {recording.rows} rows of {recording.coordinates} coordinates in "
          f"{recording.wall_time_s:.1f} s; opening Exudyn's viewer (close its window or press Q to end)", flush=True)
    show_solution(recording)
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from weftsim.api import compare
    from weftsim.post.compare import format_report, verdict
    from weftsim.post.output import prepare_directory, to_json

    scene = scene_from_args(args)
    outdir = output_directory(args, scene, "compare")
    _check_fits(scene, outdir, runs=2)
    prepare_directory(outdir, args.force, scene, kind="compare", create=False)  # refused before the estimate
    with _stdout_to_stderr() if args.json else contextlib.nullcontext():  # the estimate imports Exudyn
        _announce_run_time(scene, ("reference", "exudyn"), "compare")  # may refuse an engine's settings
        prepare_directory(outdir, args.force, scene, kind="compare")  # created once nothing refuses the run
        _announce_checks(scene, "compare")
        report = compare(scene, outdir, solve=_solve, force=args.force)
        status, problem = verdict(report, outdir)
    print(to_json(report) if args.json else format_report(report), end="" if args.json else "\n")
    if status:
        raise CliError(problem, status)
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from weftsim.api import resolve_engine
    from weftsim.sweep import format_report, plan_sweep, run_sweep

    engine = resolve_engine(args.engine) if args.engine in ENGINE_CHOICES else args.engine
    fixed = _fixed_overrides(args)  # the shorthand flags are fixed overrides of every cell, as --set is
    with terminated_as_interrupt():
        return _run_sweep(args, engine, fixed)


def _run_sweep(args: argparse.Namespace, engine: str, fixed: list[str]) -> int:
    from weftsim.sweep import format_report, plan_sweep, run_sweep

    try:
        plan = plan_sweep(args.scene, args.vary, fixed, engine, allow_large=args.yes,
                          allow_cwd_engine=args.allow_cwd_engine,
                          announce=lambda line: print(line, file=sys.stderr, flush=True))
        for note in plan.notes:
            print(f"weftsim sweep: {note}", file=sys.stderr, flush=True)
        outdir = output_directory(args, plan.base, "sweep-" + engine.replace(":", "."))
        report = run_sweep(plan, outdir, jobs=args.jobs, scheduler=args.scheduler, cell_figures=args.cell_figures)
    except Terminated as exc:
        name = signal.Signals(exc.signum).name
        raise CliError(f"terminated by {name}; finished cells are kept, run the same command again to resume",
                       128 + exc.signum) from None
    print(format_report(report))
    if report.failed:
        raise CliError(f"{report.failed} of {report.total} cells failed (see {report.table} and each failed cell's "
                       "error.txt)", EXIT_FAILED)
    return 0


def cmd_study(args: argparse.Namespace) -> int:
    from weftsim.api import scene_overrides
    from weftsim.studies import STUDIES, check_overrides, format_study, run_study
    from weftsim.studies.common import wrote_lines

    names = list(STUDIES) if args.name == "all" else [args.name]
    overrides = scene_overrides(set_overrides(args), where="command line", **shorthand_values(args))
    revolutions = overrides.pop("drive.revolutions", None)
    for name in names:  # every refusal before the first study runs
        check_overrides(name, overrides, revolutions)
    models = models_directory(args)
    parent, tag = Path("out"), overrides_tag(command_overrides(args))
    if args.scene is not None:  # a bad scene or override refused before the first study runs
        from weftsim.input.scene import load_scene

        parent = output_directory(argparse.Namespace(**{**vars(args), "output": None}),
                                  load_scene(args.scene, {**overrides, "drive.revolutions": revolutions}))
        tag = ""  # in the scene's directory's name
    for name in names:
        outdir = (Path(args.output) / name if args.name == "all" else Path(args.output)) if args.output \
            else parent / (f"study-{name}-{tag}" if tag else f"study-{name}")
        report = run_study(name, outdir, models, revolutions, args.force, overrides=overrides, scene=args.scene)
        print(format_study(name, report))
        print("\n".join(wrote_lines(outdir, report)))
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    from weftsim.bench import CASES, run_benchmark

    unknown = [c for c in args.case or [] if c not in CASES]
    if unknown:
        raise CliError(f"unknown --case {', '.join(unknown)}; choose from {', '.join(CASES)}")
    if args.targets:
        from weftsim.bench.targets import run_targets, write_targets

        report = run_targets(models_directory(args), repeats=args.repeats, log=lambda text: print(text, file=sys.stderr))
        files = write_targets(report, args.output or "out/bench-targets", args.force)
        print(f"targets measured in {report['total_time_s']:.0f} s; wrote " + ", ".join(map(str, files)))
        return 0
    outdir = args.output or ("out/bench-quick" if args.quick else "out/bench")
    report = run_benchmark(outdir, models_directory(args), args.quick, args.case, repeats=args.repeats, force=args.force)
    print(f"benchmark done in {report['total_time_s']:.0f} s; wrote " + ", ".join(map(str, report["files"])))
    return 0


def cmd_scenes(args: argparse.Namespace) -> int:
    """``weftsim scenes``: each bundled scene's name and description, one a line."""
    from weftsim.input.scene import bundled_directory, bundled_scene_path, bundled_scenes, scene_description

    names = bundled_scenes()
    if not names:
        raise CliError("this installation has no bundled scenes")
    width = max(map(len, names))
    print(f"bundled scenes in {bundled_directory()} (weftsim run NAME; a scene file may extends = \"NAME\"):")
    for name in names:
        print(f"  {name:{width}s}  {scene_description(bundled_scene_path(name))}")
    return 0


COMMANDS = {"scenes": cmd_scenes, "kinematics": cmd_kinematics, "run": cmd_run, "animate": cmd_animate,
            "compare": cmd_compare,
            "sweep": cmd_sweep, "optimize": cmd_optimize, "study": cmd_study, "bench": cmd_bench, "wear": cmd_wear, "bearing": cmd_bearing}


def _one_line(text: object) -> str:
    """A message as one terminal line: newlines and escape sequences from file names or values escaped."""
    from weftsim.input.scene import shown

    return shown(str(text))


def main(argv: list[str] | None = None) -> int:
    from weftsim.cli.startup import skip_final_collection

    try:
        return _main(argv)
    finally:
        skip_final_collection()  # the process ends: 0.3-0.45 s of Python's last garbage collection spared


def _main(argv: list[str] | None) -> int:
    from weftsim.cli.startup import release

    argv = sys.argv[1:] if argv is None else argv
    # The command is the first word that is not an option (the top level's options take no value): only its
    # flags are built (build_parser); no command, or a mistyped one, builds them all.
    command = next((word for word in argv if not word.startswith("-")), None)
    parser = build_parser(command if command in COMMANDS else None)  # still weftsim.cli.startup's SIGINT handler
    args = parser.parse_args(argv)
    set_command(argv)  # recorded in every output directory (weftsim.post.record)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(name)s: %(message)s")
    release()  # from here a Ctrl-C is a KeyboardInterrupt again, caught below and by the commands
    try:
        return COMMANDS[args.command](args)
    except WeftsimError as exc:  # its message is the line to print, its class the exit status
        print(f"weftsim {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_status
    except MemoryError:
        print(f"weftsim {args.command}: error: out of memory; use a coarser output.sample_deg or fewer "
              "drive.revolutions", file=sys.stderr)
        return EXIT_FAILED
    except BrokenPipeError:
        # The reader of stdout is gone (`weftsim ... | head`): nothing more can be shown, and the
        # files were written before the report.  Point stdout at /dev/null so that Python's final
        # flush does not fail again, and end as a Unix tool does on SIGPIPE, without a message.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        print(f"weftsim {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except ImportError as exc:
        # Ctrl-C while a compiled module loads (Exudyn's) surfaces as that module's ImportError: an interruption
        if isinstance(exc.__context__, KeyboardInterrupt) or isinstance(exc.__cause__, KeyboardInterrupt):
            print(f"weftsim {args.command}: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
        raise


if __name__ == "__main__":
    sys.exit(main())
