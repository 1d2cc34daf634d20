"""The ``weftsim wear`` subcommand: flags and the run (the CLI module only wires it in)."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from weftsim.errors import EXIT_FAILED
from weftsim.checks.progress import format_duration

if TYPE_CHECKING:
    import argparse
    from collections.abc import Callable
    from contextlib import AbstractContextManager
    from pathlib import Path

    from weftsim.input.params import Scene


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
                        "effective clearance reaches it and the first of them (the joint to service first)")
    p.add_argument("--no-plot", action="store_true", help="skip the figures")
    ens = p.add_argument_group("ensemble (docs/wear.md section 7)")
    ens.add_argument("--uncertain", action="append", default=[], metavar="KEY=DISTRIBUTION",
                     help="an uncertain scene key, in its file units: normal(mean,sd), lognormal(median,sigma_of_log), "
                          "uniform(low,high) or triangular(low,mode,high); repeatable. Needs --limit-clearance-mm")
    ens.add_argument("--samples", type=int, default=1000, help="ensemble samples (default 1000; cost no simulation)")
    ens.add_argument("--seed", type=int, default=0, help="seed of the ensemble's sampling (default 0)")
    ens.add_argument("--chaos-runs", type=int, default=6, help="predictions of the nominal design point differing "
                     "in the last bits of k, sampling the chaotic scatter (default 6)")
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
    if args.hours is None and limit is None:
        raise CliError("--hours or --limit-clearance-mm is required (or --uncertain KEY=DISTRIBUTION with "
                       "--limit-clearance-mm for an ensemble)")
    until_limit = args.hours is None  # predict until the clearance limit
    hours = MAX_HOURS if until_limit else args.hours
    check_request(scene, hours, args.engine, limit)  # a WearError is one line, exit 2
    outdir = prepare_directory(outdir, args.force, scene)
    try:
        check_engine(outdir, args.engine, args.force)  # a state of the other engine: one line, or --force
    except StateMismatch as exc:
        raise CliError(str(exc)) from None
    resumed = _stored_updates(outdir, scene, args.force)
    from weftsim.wear.extrapolate import joint_of, wearing_joints

    joints = wearing_joints(scene)
    first = joint_of(scene, joints[0]).wear
    at = " and ".join(j.upper() for j in joints)
    span = f"until the clearance reaches {args.limit_clearance_mm:g} mm" if until_limit else f"over {hours:g} h"
    print(f"scene {scene.name}, wear at {at} {span} on the {args.engine} engine; each update simulates "
          f"{first.settle_revolutions} + {first.revolutions_per_update} revolutions "
          f"(~{_duration(update_time(scene, args.engine))}), the update interval grows each clearance by at most "
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
                                        force=args.force, until_limit=until_limit)
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
    if limit is not None:
        reached = data.get("hours_to_limit")
        each = ", ".join(f"{j.upper()} " + (f"{data[f'hours_to_limit_{j}']:.6g} h"
                                           if data.get(f"hours_to_limit_{j}") is not None else "not reached")
                         for j in joints)
        print(f"  clearance limit {args.limit_clearance_mm:g} mm: reached first at {data['limit_joint'].upper()} "
              f"after {reached:.6g} h ({each})" if reached is not None else f"  {data['note']}")
    for path in data["files"].values():
        print(f"  wrote {path}")
    if data.get("ended"):
        asked = "" if until_limit else f" of the {hours:g} asked for"
        print(f"  the prediction ends at {data['hours_reached']:.6g} h{asked}: {data['ended']}; nothing beyond "
              "it is predicted")
        return 0
    if not data["complete"]:
        raise CliError(f"interrupted: stopped after {data['hours_reached']:.6g} h; the state is in {outdir}: run the "
                        "same command again to resume", 130)
    return 0


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
    limit = args.limit_clearance_mm * 1e-3
    try:
        data = wear_ensemble(scene, args.uncertain, args.samples, limit, outdir, jobs=args.jobs,
                             scheduler=args.scheduler, seed=args.seed, figures=not args.no_plot, force=args.force,
                             chaos_runs=args.chaos_runs, design_points=design_points,
                             levels=tuple(1e-3 * v for v in args.level_mm),
                             announce=lambda text: print(text, file=sys.stderr, flush=True),
                             **({} if args.hours is None else {"horizon": args.hours}))
    except WearError as exc:
        raise CliError(str(exc)) from None
    except KeyboardInterrupt:
        raise CliError(f"interrupted: every job's updates so far are in {outdir}/jobs; run the same command again "
                       "to resume", 130) from None
    m = data["method"]
    print(f"scene {scene.name}: hours to an effective clearance of {args.limit_clearance_mm:g} mm at E, "
          f"{data['samples']} samples ({len(data['jobs'])} simulated predictions, {data['wall_time_s']:.0f} s)")
    from weftsim.wear.censored import text_hours

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
              f"{text_hours(q['low'], horizon)} - {text_hours(q['high'], horizon)})")
    if reach["fraction"] < 1.0 and data.get("hours_of_those_reaching"):
        print("  of those reaching it: " + ", ".join(f"{name} {text_hours(q['hours'], horizon)}" for name, q in
                                                     data["hours_of_those_reaching"].items()))
    print("  shares of the spread: " + ", ".join(f"{k} {100 * v['share']:.0f} %" for k, v in
                                                 sorted(data["shares"].items(), key=lambda kv: -kv[1]["share"])))
    for path in data["files"].values():
        print(f"  wrote {path}")
    return 0
