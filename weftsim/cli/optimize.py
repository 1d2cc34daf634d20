"""``weftsim optimize``: the flags, and the command over :mod:`weftsim.optimize` (thin: parse, call, report)."""

from __future__ import annotations

import argparse
import signal
import sys

def add_flags(p: argparse.ArgumentParser, positive, add_scene_flags) -> None:
    from weftsim.optimize.constraints import BOUNDED, FLAGS
    from weftsim.optimize.objectives import OBJECTIVES

    p.add_argument("scene", help="base scene: a scene file (TOML) or the name of a bundled scene")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=LOW:HIGH",
                   help="a design key and its bounds (file units, e.g. l_oe_mm=200:280), or a choice KEY=A,B,C; "
                   "repeat for more keys")
    p.add_argument("--objective", action="append", required=True, metavar="NAME",
                   help=f"minimise this ({', '.join(OBJECTIVES)}); twice for a Pareto front of two")
    p.add_argument("--constraint", action="append", default=[], metavar="NAME=LOW:HIGH",
                   help=f"keep {', '.join(BOUNDED)} within bounds (either may be left out: "
                   f"transmission_angle_deg=40:), or {', '.join(FLAGS)} (the bushing's limits); the linkage's "
                   "assembly always")
    p.add_argument("--at-clearance-mm", type=float, default=None,
                   help="the worn joint's radial clearance at E, mm, at which the worn-joint objectives are run "
                   "(default: the scene's joint_e.clearance_mm)")
    p.add_argument("--max-evaluations", type=positive(int), default=200,
                   help="designs whose objectives may be evaluated (default 200); a design violating a "
                   "constraint costs only its kinematics")
    p.add_argument("--population", type=positive(int), default=10,
                   help="differential evolution's population per design key (default 10)")
    p.add_argument("--front-points", type=positive(int), default=5,
                   help="two objectives: DE runs along the front, the two single optima included (default 5)")
    p.add_argument("--seed", type=int, default=1, help="seed of the optimiser (default 1): same seed, same result")
    p.add_argument("--engine", default="reference",
                   help="engine of the dynamic runs: reference (default), exudyn, auto, or module:function")
    p.add_argument("--allow-cwd-engine", action="store_true",
                   help="allow a --engine module:function found in the current directory (refused by default)")
    p.add_argument("--jobs", type=positive(int), help="local worker processes (default: number of CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the designs on an existing Dask cluster")
    p.add_argument("--compare", action="store_true",
                   help="re-run the start and best design(s) on both engines at the worn clearance "
                   "(weftsim compare into compare-*/)")
    add_scene_flags(p, positional=False)
    p.add_argument("-o", "--output", default=None, help="output directory (default: out/<scene name>/optimize)")


def run(args: argparse.Namespace, fixed: list[str]) -> int:
    """Plan, run and report; ``fixed``: the ``--set`` and shorthand overrides as ``KEY=VALUE`` texts."""
    from weftsim.cli.grammar import CliError, output_directory
    from weftsim.cli.signals import Terminated, terminated_as_interrupt
    from weftsim.errors import EXIT_FAILED
    from weftsim.optimize import format_report, plan_problem, run_problem

    problem = plan_problem(args.scene, args.vary, args.objective, args.constraint, fixed, args.engine,
                           args.at_clearance_mm, args.allow_cwd_engine)
    outdir = output_directory(args, problem.base, "optimize")
    try:
        with terminated_as_interrupt():
            report = run_problem(problem, outdir, max_evaluations=args.max_evaluations, seed=args.seed,
                                 population=args.population, front_points=args.front_points, jobs=args.jobs,
                                 scheduler=args.scheduler, compare=args.compare)
    except KeyboardInterrupt as exc:
        how = signal.Signals(exc.signum).name if isinstance(exc, Terminated) else "Ctrl-C"
        status = 128 + (exc.signum if isinstance(exc, Terminated) else signal.SIGINT)
        raise CliError(f"stopped by {how}: the designs evaluated are kept in {outdir}/evaluations.jsonl; run the "
                        "same command again to resume (the same seed gives the same result)", status) from None
    print(format_report(report))
    if not report.feasible:
        print(f"weftsim optimize: {report.message}", file=sys.stderr)
        return EXIT_FAILED
    return 0
