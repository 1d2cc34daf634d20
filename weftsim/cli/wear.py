"""The ``weftsim wear`` subcommand: flags and the run (the CLI module only wires it in)."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from weftsim.errors import EXIT_FAILED
from weftsim.checks.progress import format_duration

if TYPE_CHECKING:
    import argparse
    from collections.abc import Callable
    from contextlib import AbstractContextManager
    from pathlib import Path

    from weftsim.input.params import Scene


# Where the docs explain ensembles: the one place the command line names it (tests/test_hostile_words.py checks
# that this section of docs/wear.md is the one about ensembles).
ENSEMBLE_SECTION = "docs/wear.md section 9"
SAMPLES, SEED, CHAOS_RUNS = 1000, 0, 6  # the ensemble's defaults (weftsim.wear.ensemble.CHAOS_RUNS: the same)
# The flags only an ensemble reads, by their argparse names: given without --uncertain they are refused.
ENSEMBLE_ONLY = ("samples", "seed", "chaos_runs", "level_mm", "design_points", "jobs", "scheduler")


def seed(text: str) -> int:
    """An argparse type: a whole number >= 0 (numpy's generators take no negative seed)."""
    import argparse

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 0, got {text!r}")
    return value


def add_flags(p: argparse.ArgumentParser, positive: Callable[[Callable[[str], float]], Callable[[str], float]]) -> None:
    """Flags of ``weftsim wear SCENE --hours H [--engine E] [--limit-clearance-mm X]`` beside the shared
    scene and output flags."""
    p.add_argument("--hours", type=positive(float), help="operating hours to predict (without it, with "
                   "--limit-clearance-mm: until the clearance reaches the limit); with --uncertain the horizon "
                   "(default 1e5): samples not reaching --limit-clearance-mm within it are reported as censored")
    p.add_argument("--engine", default="reference", help="engine of each update's simulation: reference (default) "
                   "or exudyn (its kinematic tree; default output out/<scene name>/wear-exudyn; docs/wear.md)")
    p.add_argument("--limit-clearance-mm", type=positive(float),
                   help="clearance limit for every wearing joint: wear.json gives the hours at which each joint's "
                        "effective clearance reaches it and the first of them (the joint to service first); the "
                        "prediction ends there (the update that crosses it is cut at it) unless --past-limit")
    p.add_argument("--past-limit", action="store_true",
                   help="with --limit-clearance-mm and --hours: go on wearing past the limit up to --hours")
    p.add_argument("--no-plot", action="store_true", help="skip the figures")
    from weftsim.wear.uncertain import ALLOWED

    ens = p.add_argument_group(f"ensemble ({ENSEMBLE_SECTION}); these flags need --uncertain")
    ens.add_argument("--uncertain", action="append", default=[], metavar="KEY=DISTRIBUTION",
                     help=f"an uncertain scene key (dotted, or its last part as --set takes it), in its file units: "
                          f"{ALLOWED} (walther: a viscosity key, from the oil's nu at 40 and 100 C and a "
                          "temperature range); repeatable. Needs --limit-clearance-mm; results in "
                          "out/<scene name>/wear-ensemble")
    ens.add_argument("--samples", type=int, default=None, help=f"ensemble samples (default {SAMPLES}; cost no "
                     "simulation)")
    ens.add_argument("--seed", type=seed, default=None, help="seed of the ensemble's sampling, a whole number "
                     ">= 0 (default 0)")
    ens.add_argument("--chaos-runs", type=int, default=None, help="predictions of the nominal design point differing "
                     f"in the last bits of k, sampling the chaotic scatter (default {CHAOS_RUNS})")
    ens.add_argument("--level-mm", action="append", type=positive(float), default=[], metavar="X",
                     help="also give the hours to an effective clearance of X mm (below the limit); repeatable")
    ens.add_argument("--design-points", action="append", default=[], metavar="KEY=N",
                     help="N design points (2-9) for a simulated --uncertain key instead of 3; repeatable")
    ens.add_argument("--jobs", type=int, help="local worker processes for the ensemble's simulations (default: cores)")
    ens.add_argument("--scheduler", help="address of a Dask scheduler to run the ensemble's simulations on")


def _duration(seconds: float) -> str:
    return f"{seconds:.2g} s" if seconds < 1.0 else format_duration(seconds)


def run(args: argparse.Namespace, scene: Scene, outdir: str | Path,
        stop_on_interrupt: Callable[[str], AbstractContextManager]) -> int:
    """Predict, report progress on stderr and the result on stdout; Ctrl-C keeps the state for a resume."""
    from weftsim.cli.grammar import CliError
    from weftsim.post.output import prepare_directory
    from weftsim.checks.progress import Progress
    from weftsim.wear import WearError, check_engine, check_request, predict_to_directory
    from weftsim.wear.extrapolate import MAX_HOURS, update_time
    from weftsim.wear.store import StateMismatch

    limit = None if args.limit_clearance_mm is None else args.limit_clearance_mm * 1e-3
    if args.uncertain:
        return run_ensemble(args, scene, outdir, stop_on_interrupt)
    given = [name for name in ENSEMBLE_ONLY if getattr(args, name) not in (None, [])]
    if given:
        flags = ", ".join("--" + name.replace("_", "-") for name in given)
        raise CliError(f"{flags} {'sets' if len(given) == 1 else 'set'} an ensemble and need(s) --uncertain "
                       "KEY=DISTRIBUTION (with --limit-clearance-mm); without --uncertain `weftsim wear` predicts "
                       "one scene: leave them out")
    if args.hours is None and limit is None:
        raise CliError("--hours or --limit-clearance-mm is required (or --uncertain KEY=DISTRIBUTION with "
                       "--limit-clearance-mm for an ensemble)")
    until_limit = args.hours is None  # predict until the clearance limit
    past_limit = bool(getattr(args, "past_limit", False))
    if past_limit and (limit is None or until_limit):
        raise CliError("--past-limit goes on wearing past --limit-clearance-mm up to --hours: give both")
    hours = MAX_HOURS if until_limit else args.hours
    check_request(scene, hours, args.engine, limit)  # a WearError is one line, exit 2
    update_seconds = update_time(scene, args.engine)  # the engine's estimate may refuse its settings: before mkdir
    outdir = prepare_directory(outdir, args.force, scene, kind="wear")
    try:
        check_engine(outdir, args.engine, args.force)  # a state of the other engine: one line, or --force
    except StateMismatch as exc:
        raise CliError(str(exc)) from None
    resumed = _stored_updates(outdir, scene, args.force)
    from weftsim.wear.extrapolate import joint_of, wearing_joints

    joints = wearing_joints(scene)
    first = joint_of(scene, joints[0]).wear
    at = " and ".join(j.upper() for j in joints)
    span = (f"until the clearance reaches {args.limit_clearance_mm:g} mm" if until_limit else f"over {hours:g} h"
            if limit is None or past_limit else f"over {hours:g} h or until the clearance reaches "
            f"{args.limit_clearance_mm:g} mm")
    print(f"scene {scene.name}, wear at {at} {span} on the {args.engine} engine; each update simulates "
          f"{first.settle_revolutions} + {first.revolutions_per_update} revolutions "
          f"(~{_duration(update_seconds)}), the update interval grows each clearance by at most "
          + ", ".join(f"{100 * joint_of(scene, j).wear.max_clearance_change:g} % at {j.upper()}" for j in joints),
          file=sys.stderr, flush=True)
    if resumed:
        print(f"resuming the prediction stored in {outdir}: {len(resumed)} updates kept, up to "
              f"{resumed[-1].hours:.6g} h", file=sys.stderr, flush=True)
    progress = Progress(f"wear {scene.name}")
    with stop_on_interrupt("wear") as state:
        try:
            data = predict_to_directory(scene, hours, outdir, args.engine, limit, progress,
                                        stop=lambda: state["signal"] is not None, figures=not args.no_plot,
                                        force=args.force, until_limit=until_limit, past_limit=past_limit)
        except StateMismatch as exc:
            raise CliError(str(exc)) from None
        except WearError as exc:  # the updates before it are written (the message says where)
            raise CliError(str(exc), EXIT_FAILED) from None
        finally:
            progress.close()
    print(f"scene {scene.name}: {data['hours_reached']:.6g} h in {data['updates']} updates "
          f"({data['wall_time_s']:.1f} s); wear volume {data['wear_volume_mm3']:.4g} mm^3")
    for j in joints:
        print(f"  at {j.upper()}: effective clearance {data[f'initial_clearance_{j}_mm']:g} -> "
              f"{data[f'final_effective_clearance_{j}_mm']:.4g} mm, wear volume {data[f'wear_volume_{j}_mm3']:.4g} mm^3")
    if data.get("backoffs"):
        print(f"  {data['backoffs']} hard cycle(s) (an update whose simulation failed at every tolerance and "
              "integrator) were passed by halving the update before them (docs/wear.md section 3)")
    for j in joints:
        if data.get(f"sliding_distance_{j}_m"):
            print(f"  Archard's check at {j.upper()}: sliding {data[f'sliding_distance_{j}_m']:.4g} m under the "
                  f"sliding-weighted mean load {data[f'sliding_weighted_mean_load_{j}_N']:.4g} N (the time mean is "
                  f"{data[f'time_mean_load_{j}_N']:.4g} N) gives {data[f'archard_volume_{j}_mm3']:.4g} mm^3; the "
                  f"profiles hold {data[f'profile_volume_{j}_mm3']:.4g} mm^3")
    for path in data["files"].values():
        print(f"  wrote {path}")
    if data.get("ended"):
        asked = "" if until_limit else f" of the {hours:g} asked for"
        at = ", ".join(f"{data[f'final_effective_clearance_{j}_mm']:.4g} mm at {j.upper()}" for j in joints)
        print(f"  the prediction ends at {data['hours_reached']:.6g} h{asked} (effective clearance {at}): "
              f"{data['ended']}; nothing beyond it is predicted")
    if limit is not None:  # the last lines: what a planner reads
        for line in limit_lines(data, joints):
            print(line)
    if data.get("ended"):
        return 0
    if not data["complete"]:
        raise CliError(f"interrupted: stopped after {data['hours_reached']:.6g} h; the state is in {outdir}: run the "
                        "same command again to resume", 130)
    return 0


def limit_lines(data: dict, joints: Sequence[str]) -> list[str]:
    """The terminal's last lines of a prediction with a clearance limit: the hours to it at each joint (and the
    calendar days where ``wear.json`` has them), or why it was not reached."""
    limit = data["limit_clearance_mm"]
    lines = []
    for j in joints:
        hours = data.get(f"hours_to_limit_{j}")
        if hours is None:
            lines.append(f"  at {j.upper()}: the limit {limit:g} mm is not reached (effective clearance "
                         f"{data[f'final_effective_clearance_{j}_mm']:.4g} mm after {data['hours_reached']:.6g} h)")
            continue
        days = data.get(f"calendar_days_to_limit_{j}")
        when = "" if days is None else f" of running = {days:.4g} calendar days ({data['duty_text']})"
        first = " (first)" if len(joints) > 1 and data.get("limit_joint") == j else ""
        share = data.get(f"stop_start_share_{j}") or 0.0
        stops = f"; {100 * share:.3g} % of the wear from stop-starts" if data.get("stops_per_hour") else ""
        lines.append(f"  at {j.upper()}{first}: {hours:.6g} h{when} to the limit {limit:g} mm{stops}")
    if data.get("hours_to_limit") is None and data.get("note"):
        lines.append(f"  {data['note']}")
    return lines


def _stored_updates(outdir: Path, scene: Scene, force: bool) -> list:
    """The updates a previous run stored in ``outdir`` (resumed); with ``force`` a state of another
    scene is deleted (the prediction starts over), without it that is refused (one line)."""
    from weftsim.cli.grammar import CliError
    from weftsim.wear import store

    try:
        return store.load_state(outdir, scene)
    except store.StateMismatch as exc:
        if not force:
            raise CliError(str(exc)) from None
        (outdir / store.STATE).unlink(missing_ok=True)
        return []


def run_ensemble(args: argparse.Namespace, scene: Scene, outdir: str | Path,
                 stop_on_interrupt: Callable[[str], AbstractContextManager]) -> int:
    """``weftsim wear SCENE --uncertain KEY=DIST ... --limit-clearance-mm X``: the hours to X as a distribution."""
    from weftsim.cli.grammar import CliError
    from weftsim.wear import WearError
    from weftsim.wear.ensemble import wear_ensemble

    if args.limit_clearance_mm is None:
        raise CliError("--uncertain needs --limit-clearance-mm: an ensemble gives the hours to that clearance")
    design_points = {}
    for text in args.design_points:
        key, _, n = text.partition("=")
        try:
            design_points[key.strip()] = int(n)
        except ValueError:
            raise CliError(f"--design-points {text!r}: give KEY=N with a whole number N from 2 to 9") from None
    if args.engine != "reference":
        raise CliError("an ensemble runs on the reference engine (--engine reference)")
    import signal

    from weftsim.cli.signals import Terminated, terminated_as_interrupt

    limit = args.limit_clearance_mm * 1e-3
    try:
        with terminated_as_interrupt():
            data = wear_ensemble(scene, args.uncertain, SAMPLES if args.samples is None else args.samples, limit,
                                 outdir, jobs=args.jobs, scheduler=args.scheduler,
                                 seed=SEED if args.seed is None else args.seed, figures=not args.no_plot,
                                 force=args.force, chaos_runs=CHAOS_RUNS if args.chaos_runs is None else args.chaos_runs,
                                 design_points=design_points, levels=tuple(1e-3 * v for v in args.level_mm),
                                 announce=lambda text: print(text, file=sys.stderr, flush=True),
                                 **({} if args.hours is None else {"horizon": args.hours}))
    except WearError as exc:
        raise CliError(str(exc)) from None
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM / SIGHUP (Terminated): the pool is shut down
        signum = exc.signum if isinstance(exc, Terminated) else signal.SIGINT
        how = "interrupted" if signum == signal.SIGINT else f"terminated by {signal.Signals(signum).name}"
        raise CliError(f"{how}: every job's updates so far are in {outdir}/jobs; run the same command again "
                       "to resume", 128 + signum) from None
    m = data["method"]
    print(f"scene {scene.name}: hours to an effective clearance of {args.limit_clearance_mm:g} mm at E, "
          f"{data['samples']} samples ({len(data['jobs'])} simulated predictions, {data['wall_time_s']:.0f} s)")
    from weftsim.wear.censored import text_hours, text_interval

    horizon, never = data["horizon_hours"], bool(data["never"])
    reach = data["reaching_limit"]
    print(f"  reaching it within {horizon:g} h: {100 * reach['fraction']:.3g} % of the samples "
          f"({100 * m['quantile_confidence']:g} % interval {100 * reach['low']:.3g} - {100 * reach['high']:.3g} %)"
          + (f"; design points that never wear: {', '.join(data['never'])}" if never else ""))
    for level, table in data["hours_by_clearance_mm"].items():
        if float(level) != args.limit_clearance_mm:
            print(f"  to {level} mm: " + ", ".join(f"{name} {text_hours(table[name]['hours'], horizon)}"
                                                   for name in ("p10", "p50", "p90"))
                  + f" ({100 * table['reaching']['fraction']:.3g} % reach it within {horizon:g} h)")
    for name, q in data["hours_to_limit"].items():
        print(f"  {name}: {text_hours(q['hours'], horizon)} ({100 * m['quantile_confidence']:g} % interval "
              f"{text_interval(q, data['samples'])})")
    if reach["fraction"] < 1.0 and data.get("hours_of_those_reaching"):
        print("  of those reaching it: " + ", ".join(f"{name} {text_hours(q['hours'], horizon)}" for name, q in
                                                     data["hours_of_those_reaching"].items()))
    days = data["calendar_days_to_limit"]
    print(f"  calendar days to {args.limit_clearance_mm:g} mm ({data['duty_text']}): " + ", ".join(
        f"{name} {text_hours(days[name]['hours'], data['horizon_calendar_days'])[:-2]} d" for name in ("p10", "p50", "p90")))
    by_shift = data.get("calendar_days_by_shift")
    if by_shift:
        at_limit = f"{args.limit_clearance_mm:.6g}"

        def shift(h: str, table: dict) -> str:
            beyond = data["horizon_calendar_days_by_shift"][h]
            return f"{h} h a day " + " / ".join(text_hours(table[at_limit][name]["hours"], beyond)[:-2]
                                               for name in ("p10", "p50", "p90")) + " d"

        print(f"  calendar days to {args.limit_clearance_mm:g} mm by shifts (p10 / p50 / p90): "
              + ", ".join(shift(h, t) for h, t in by_shift.items()))
    stops = data.get("stop_start_share")
    if stops:
        centre = stops["centre"] is not None
        at = "the centre design point" if centre else "the median of the design points"
        print(f"  wear from stop-starts: {100 * (stops['centre'] if centre else stops['median']):.3g}"
              f" % of the worn volume at {at} ({100 * stops['min']:.3g} - {100 * stops['max']:.3g} % over the "
              f"{len(stops['by_design_point'])} simulated predictions)")
    if reach["fraction"] == 0.0:
        print(f"  shares of the spread: none (no sample reaches {args.limit_clearance_mm:g} mm within {horizon:g} h: "
              "the ranks are all tied)")
        for path in data["files"].values():
            print(f"  wrote {path}")
        return 0
    if any(v["share"] > 0.0 for v in data["shares"].values()):
        print("  shares of the spread: " + ", ".join(f"{k} {100 * v['share']:.0f} %" for k, v in
                                                     sorted(data["shares"].items(), key=lambda kv: -kv[1]["share"])))
    else:
        print("  shares of the spread: none (the hours to the limit are the same in every sample)")
    for path in data["files"].values():
        print(f"  wrote {path}")
    return 0
