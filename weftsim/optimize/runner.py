"""Planning and running an optimisation into its directory (``weftsim optimize``; ``weftsim.optimize(...)``).

1. plan (:func:`plan_problem`): the design keys and bounds, objectives and constraints parsed and checked, the
   base scene loaded and the engine checked, nothing run;
2. run (:func:`run_problem`): the directory checked (a new one, or one holding this problem: resumed; another
   command's or problem's is refused) and locked, the start design evaluated, then the DE run(s) of
   :mod:`weftsim.optimize.driver`, each design's runs on the sweep's pool, progress on stderr;
3. report: ``optimum.json``, ``designs.csv`` and the figures (:mod:`weftsim.optimize.report`), and with
   ``compare`` the start and best designs re-run on both engines at the worn clearance (``weftsim compare``
   into ``compare-start/``, ``compare-best-N/``).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from weftsim.errors import OptimizeError, SceneError, SweepError
from weftsim.optimize.constraints import check_constraints, parse_constraint
from weftsim.optimize.evaluate import Evaluator, Problem
from weftsim.optimize.objectives import OBJECTIVES, check_objectives
from weftsim.optimize.problem import check_variables, parse_variable, start_design

if TYPE_CHECKING:
    from typing import TextIO

log = logging.getLogger(__name__)

KIND = "optimize"
MAX_EVALUATIONS = 100_000  # a budget beyond this is a typo (the loom's dynamic objective: ~0.3 s a design and core)


@dataclass
class OptimizeReport:
    """What an optimisation found (``optimum.json``'s content in :attr:`data`) and the files it wrote."""

    outdir: Path
    feasible: bool
    binding: str | None
    message: str
    data: dict
    files: dict[str, Path] = field(default_factory=dict)
    wall_time_s: float = 0.0


def plan_problem(scene: str | Path, vary: list[str], objectives: list[str], constraints: list[str] | tuple = (),
                 fixed: list[str] | tuple = (), engine: str = "reference", at_clearance_mm: float | None = None,
                 allow_cwd_engine: bool = False) -> Problem:
    """Parse and check everything of an optimisation before anything runs (one OptimizeError line otherwise)."""
    from weftsim.input.scene import load_scene, to_file_keys
    from weftsim.sweep.engines import check_engine
    from weftsim.sweep.grid import parse_set
    from weftsim.sweep.cell import normalise

    if isinstance(vary, str) or isinstance(objectives, str) or isinstance(constraints, str):
        raise OptimizeError("vary, objectives and constraints are lists of texts (['l_oe_mm=200:280'], "
                            "['peak_joint_force'], ['stroke_mm=1200:1300']), not one text")
    variables = [parse_variable(text) for text in vary]
    check_variables(variables)
    parsed = [parse_constraint(text) for text in constraints]
    check_constraints(parsed)
    try:
        fixed_overrides = dict(parse_set(text) for text in fixed)
        check_engine(engine, allow_cwd_engine)
    except SweepError as exc:
        raise OptimizeError(str(exc)) from None
    both = sorted({v.key for v in variables} & set(fixed_overrides))
    if both:
        raise OptimizeError(f"key(s) {', '.join(both)} both varied (--vary) and fixed (--set)")
    base = load_scene(scene, fixed_overrides, refuse_ideal_keys=False)
    names = check_objectives(list(objectives), at_clearance_mm, base.joint.clearance * 1e3)
    return Problem(str(scene), base, normalise(to_file_keys(base)), engine, tuple(variables), names, tuple(parsed),
                   at_clearance_mm, fixed_overrides)


def _open(outdir: Path, problem: Problem) -> dict:
    from weftsim.optimize.store import open_store, problem_record
    from weftsim.post.output import OutputError, begin_directory, prepare_directory

    if outdir.exists() and not outdir.is_dir():
        raise OptimizeError(f"output directory {outdir} exists and is not a directory; choose another -o")
    try:
        prepare_directory(outdir, scene=problem.base, kind=KIND)
    except OutputError as exc:
        raise OptimizeError(str(exc)) from None
    record = problem_record(problem.base_keys, problem.engine, [v.as_dict() for v in problem.variables],
                            problem.objectives, problem.at_clearance_mm)
    open_store(outdir, record)
    what = {"kind": KIND, "scene": problem.base.name}
    begin_directory(outdir, what)  # the manifest: a resumed run finds this directory its own
    return what


def run_problem(problem: Problem, outdir: str | Path, *, max_evaluations: int = 200, seed: int = 1,
                population: int = 10, front_points: int = 5, jobs: int | None = None, scheduler: str | None = None,
                compare: bool = False, progress: bool = True, stream: TextIO | None = None) -> OptimizeReport:
    """Run ``problem`` into ``outdir`` (module docstring); resumes what ``outdir`` holds of it.

    Raises
    ------
    OptimizeError
        A bad budget, population or front size; ``outdir`` holds another command's results or another problem,
        or is in use by a running optimisation.
    KeyboardInterrupt
        After ending the workers; every design evaluated is kept in ``evaluations.jsonl`` (rerun to resume).
    """
    from weftsim.optimize.driver import optimise
    from weftsim.sweep.lock import SweepLock
    from weftsim.sweep.pool import SweepProgress

    for value, name, low in ((max_evaluations, "max_evaluations (--max-evaluations)", 1),
                             (population, "population (--population)", 5), (front_points, "front_points", 3)):
        if isinstance(value, bool) or not isinstance(value, int) or value < low or value > MAX_EVALUATIONS:
            raise OptimizeError(f"{name} must be a whole number from {low} to {MAX_EVALUATIONS}, got {value!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise OptimizeError(f"seed (--seed) must be a whole number >= 0, got {seed!r}")
    outdir = Path(outdir)
    lock = SweepLock(outdir)
    start_time = time.perf_counter()
    evaluator = None
    interrupted = True
    try:
        what = _open(outdir, problem)
        lock.acquire()
        bar = SweepProgress(max_evaluations + 1, 0, stream, what="optimize", unit="designs evaluated") \
            if progress else None
        counted = [0, 0]  # designs evaluated, of which failed

        def tick(entry: dict) -> None:
            counted[0] += 1
            counted[1] += entry["status"] != "success"
            if bar is not None:
                bar.update(min(counted[0], max_evaluations + 1), counted[1])

        evaluator = Evaluator(problem, outdir, jobs, scheduler, on_evaluated=tick)
        if evaluator.resumed:
            log.info("optimize %s: %d designs evaluated before, resumed", outdir, evaluator.resumed)
        start = start_design(problem.base, problem.variables)
        start_checked = evaluator.check(start)
        if start_checked.feasible:
            evaluator.evaluate([start])
        runs, best = optimise(evaluator, seed, max_evaluations, population, front_points, start)
        interrupted = False
        if bar is not None:
            bar.update(min(counted[0], max_evaluations + 1), counted[1], final=True)
    finally:
        if evaluator is not None:
            evaluator.close(interrupted)
        if interrupted:
            lock.release()
    try:
        report = _report(problem, evaluator, outdir, what, runs, best, start, seed, max_evaluations,
                         time.perf_counter() - start_time, compare)
    finally:
        lock.release()
    return report


def _report(problem: Problem, evaluator: Evaluator, outdir: Path, what: dict, runs: list, best: list[str],
            start, seed: int, budget: int, wall: float, compare: bool) -> OptimizeReport:
    from weftsim.optimize.report import (CONVERGENCE_FILE, DESIGNS_FILE, OPTIMUM_FILE, PARETO_FILE, binding,
                                         convergence_figure, design_entry, designs_table, pareto_figure)
    from weftsim.optimize.store import EVALUATIONS_FILE, PROBLEM_FILE
    from weftsim.post.output import write_figure, write_files, write_json, write_text

    names = problem.objectives
    units = {n: OBJECTIVES[n].unit for n in names}
    feasible = bool(best)
    bound, message = (None, "") if feasible else binding(evaluator)
    checked = list(evaluator.checked.values())
    counts: dict[str, int] = {}
    for c in checked:
        for name in c.judged:
            if c.judged[name]["violation"]:
                counts[name] = counts.get(name, 0) + 1
    failed = sum(1 for e in evaluator.stored.values() if e["status"] != "success")
    best_entries = [design_entry(evaluator, evaluator.checked[i]) for i in best]
    data: dict[str, Any] = {
        "kind": KIND, "scene": problem.base.name, "scene_path": problem.scene_path, "engine": problem.engine,
        "design_keys": [v.as_dict() for v in problem.variables],
        "objectives": [{"name": n, "unit": units[n], "doc": OBJECTIVES[n].doc} for n in names],
        "at_clearance_mm": problem.at_clearance_mm,
        "new_clearance_mm": problem.base.joint.clearance * 1e3,
        "constraints": [c.as_dict() for c in problem.constraints],
        "seed": seed, "max_evaluations": budget,
        "designs": {"proposed": len(checked), "violating": sum(1 for c in checked if not c.feasible),
                    "evaluated": len(evaluator.stored), "run_now": evaluator.run_count,
                    "from_log": evaluator.resumed, "failed": failed, "violations_by_constraint": counts},
        "feasible": feasible, "binding_constraint": bound, "infeasible": message,
        "start": design_entry(evaluator, evaluator.check(start)),
        "best": best_entries,
        "de_runs": [{"label": r.label, "stop": r.stop, "evaluations": len(r.requested), "history": r.history,
                     "best": r.best and evaluator.checked[r.best].design.overrides(problem.variables)} for r in runs],
        "wall_time_s": wall,
    }
    if compare and feasible:
        data["compare"] = compare_designs(problem, evaluator, outdir, start, [evaluator.checked[i] for i in best])
    title = (f"{problem.base.name}, {problem.engine} engine"
             + (f", worn joint c = {problem.at_clearance_mm:g} mm" if problem.at_clearance_mm else ""))
    files: dict[str, tuple[str, Callable[[Path], Path]]] = {
        "optimum": (OPTIMUM_FILE, lambda t: write_json(t, data)),
        "designs": (DESIGNS_FILE, lambda t: write_text(t, designs_table(evaluator))),
        "convergence": (CONVERGENCE_FILE, lambda t: write_figure(t, convergence_figure(runs, names, units, title))),
        "problem": (PROBLEM_FILE, lambda t: t), "evaluations": (EVALUATIONS_FILE, lambda t: t),
    }
    if len(names) == 2:
        from weftsim.optimize.driver import feasible_values

        values = feasible_values(evaluator, names)
        front = [values[i] for i in best]
        start_values = tuple((data["start"]["objectives"] or {}).get(n) for n in names)
        files["pareto"] = (PARETO_FILE, lambda t: write_figure(t, pareto_figure(
            list(values.values()), front, start_values, names, units, title)))
    written = write_files(outdir, what, files, scene=problem.base)
    return OptimizeReport(outdir, feasible, bound, message, data, written, wall)


COMPARE_DESIGNS = 3  # of a front: its two ends and its middle are re-run on both engines


def compare_designs(problem: Problem, evaluator: Evaluator, outdir: Path, start, best: list) -> list[dict]:
    """The start and best design(s) on both engines at the worn clearance: each engine's objectives and the
    ``weftsim compare`` verdict (its files in ``compare-<label>/``)."""
    from weftsim.engines import simulate
    from weftsim.input.scene import scene_from_keys
    from weftsim.optimize.objectives import objective_values, run_metrics, solve_design
    from weftsim.post.compare import run_compare

    if len(best) > COMPARE_DESIGNS:
        best = [best[0], best[len(best) // 2], best[-1]]
    out = []
    for label, checked in [("start", evaluator.check(start))] + [(f"best-{k + 1}", c) for k, c in enumerate(best)]:
        scenes = evaluator.run_scenes(checked) if evaluator.runs else {}
        entry: dict[str, Any] = {"design": label, "keys": checked.design.overrides(problem.variables)}
        if not scenes:  # the ideal mechanism's objectives: the same on every engine
            out.append(entry)
            continue
        results: dict[str, Any] = {}

        def solve(scene, engine, results=results):
            results[engine] = simulate(scene, engine, on_warning=lambda text: None)
            return results[engine]

        try:
            report, _, _ = run_compare(scene_from_keys(scenes["worn"], f"design {label}"), outdir / f"compare-{label}",
                                       solve, force=True)
            entry["compare"] = {"agree": report.get("agree"), "directory": f"compare-{label}"}
        except (SceneError, OSError) as exc:
            entry["compare"] = {"agree": None, "error": str(exc)}
        engines = {}
        for engine in ("reference", "exudyn"):
            runs = {"worn": run_metrics(results[engine])} if engine in results and results[engine].ok else {}
            if "new" in scenes:
                new = solve_design(label, scenes["new"], engine)
                if new["status"] == "success":
                    runs["new"] = new["metrics"]
            engines[engine] = objective_values(problem.objectives, checked.ideal, runs)
        entry["engines"] = engines
        out.append(entry)
    return out


def format_report(report: OptimizeReport) -> str:
    """A few lines for the command line: the start and best designs, their keys and objectives."""
    data = report.data
    names = [o["name"] for o in data["objectives"]]
    units = {o["name"]: o["unit"] for o in data["objectives"]}
    d = data["designs"]
    lines = [f"optimize {report.outdir}: {d['proposed']} designs proposed, {d['violating']} violating a constraint, "
             f"{d['evaluated']} evaluated ({d['from_log']} from an earlier run, {d['failed']} failed), "
             f"{report.wall_time_s:.1f} s wall time"]

    def show(label: str, entry: dict) -> str:
        keys = ", ".join(f"{k} = {_short(v)}" for k, v in entry["keys"].items())
        objectives = entry["objectives"] or {}
        values = ", ".join(f"{n} = {_short(objectives.get(n))} {units[n]}" for n in names)
        state = "" if entry["feasible"] else f" (violates {', '.join(entry['violated'])})"
        return f"  {label}: {keys}; {values or entry['status']}{state}"

    lines.append(show("start", data["start"]))
    if not report.feasible:
        lines.append(f"  {report.message}")
    for k, entry in enumerate(data["best"]):
        lines.append(show("best" if len(data["best"]) == 1 else f"front {k + 1}", entry))
    for entry in data.get("compare", []):
        if "engines" not in entry:
            continue
        parts = [f"{engine}: " + ", ".join(f"{n} = {_short(values.get(n))}" for n in names)
                 for engine, values in entry["engines"].items()]
        agree = entry.get("compare", {}).get("agree")
        lines.append(f"  {entry['design']} on both engines: {'; '.join(parts)}; compare agree = {agree}")
    for path in report.files.values():
        lines.append(f"  wrote {path}")
    return "\n".join(lines)


def _short(value: Any) -> str:
    if isinstance(value, float) and math.isfinite(value):
        return f"{value:.5g}"
    return str(value)
