"""Judging and evaluating designs: the constraints in this process (cheap), the runs on the sweep's pool.

:class:`Evaluator` holds what an optimisation has learnt about each design: its constraints (judged on the
ideal mechanism the first time the optimiser proposes it, :mod:`weftsim.optimize.constraints`) and, for a
design that keeps them, its objectives.  A batch of designs (a generation of differential evolution) is
evaluated at once: the designs already in ``evaluations.jsonl`` are answered from there, the runs of the
others are sent as scene data to the local process pool or the Dask cluster of ``weftsim sweep``
(:func:`weftsim.sweep.pool.executor`, workers started once for the whole optimisation), and each design is
appended to the log as soon as its runs are back.  Objectives that need no run (``ideal_*``) are computed
here.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from weftsim.optimize.constraints import Constraint, feasible, judge
from weftsim.optimize.objectives import OBJECTIVES, objective_values, runs_needed, solve_design
from weftsim.optimize.problem import Design, Variable, design_geometry
from weftsim.optimize.store import EvaluationLog, normalise, read_evaluations

if TYPE_CHECKING:
    from weftsim.input.params import Scene

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Problem:
    """A validated optimisation problem (nothing run): the base scene, design keys, objectives, constraints."""

    scene_path: str
    base: Scene
    base_keys: dict
    engine: str
    variables: tuple[Variable, ...]
    objectives: tuple[str, ...]
    constraints: tuple[Constraint, ...]
    at_clearance_mm: float | None
    fixed: dict = field(default_factory=dict)


@dataclass
class Checked:
    """A design's constraints (and the ideal mechanism's objectives) as judged in this process."""

    design: Design
    judged: dict
    feasible: bool
    scene: Any  # its validated Scene, or None
    ideal: dict


class Evaluator:
    """Constraints and objectives of designs, cached; runs on the sweep's pool (module docstring)."""

    def __init__(self, problem: Problem, outdir: Path, jobs: int | None = None, scheduler: str | None = None,
                 on_evaluated: Callable[[dict], None] | None = None):
        self.problem = problem
        self.runs = runs_needed(problem.objectives)
        self.stored = read_evaluations(outdir, problem.objectives, len(problem.variables))
        self.resumed = len(self.stored)
        self.log = EvaluationLog(outdir)
        self.checked: dict[str, Checked] = {}
        self.jobs, self.scheduler = jobs, scheduler
        self.pool: Any = None
        self.stop_pool: Callable[..., None] | None = None
        self.on_evaluated = on_evaluated
        self.run_count = 0  # designs run by this process (not answered from the log)

    # --- constraints ------------------------------------------------------------------------------------------
    def check(self, design: Design) -> Checked:
        known = self.checked.get(design.id)
        if known is not None:
            return known
        from weftsim.checks.design_checks import before_run, joint_checks_before
        from weftsim.errors import SceneError
        from weftsim.input.scene import apply_overrides
        from weftsim.optimize.objectives import ideal_values

        p = self.problem
        overrides = design.overrides(p.variables)
        geometry = design_geometry(p.base, overrides)
        scene, error = None, ""
        try:
            scene = apply_overrides(p.base, {**overrides, "name": f"{p.base.name}[design]"}, "design",
                                    refuse_ideal_keys=False)
        except SceneError as exc:
            error = str(exc)
        found: list[dict] = []

        def checks() -> list[dict]:  # the before-run design checks, computed once and only when asked for
            if scene is not None and not found:
                before = before_run(scene)
                if "e" not in scene.loose_joints:  # the ideal joint at E: its loads are still the pin's
                    before = joint_checks_before(scene, "e") + before
                found.extend(c.as_dict() for c in before)
            return found

        judged = judge(p.constraints, geometry, scene, error, checks)
        ok = feasible(judged)
        wanted = ok and any(not OBJECTIVES[name].runs for name in p.objectives)
        checked = Checked(design, judged, ok, scene, ideal_values(checks()) if wanted else {})
        self.checked[design.id] = checked
        return checked

    # --- objectives -------------------------------------------------------------------------------------------
    def run_scenes(self, checked: Checked) -> dict[str, dict]:
        """The scene data of each run the objectives need ("worn", "new")."""
        from weftsim.input.scene import apply_overrides, to_file_keys

        out = {}
        for label in self.runs:
            scene = checked.scene
            at = self.problem.at_clearance_mm
            if label == "worn" and at is not None:
                scene = apply_overrides(scene, {"joint_e.clearance_mm": at}, "--at-clearance-mm",
                                        refuse_ideal_keys=False)
            keys = normalise(to_file_keys(scene))
            out[label] = {k: v for k, v in keys.items() if v is not None}
        return out

    def evaluate(self, designs: list[Design]) -> list[dict]:
        """The stored entry of each (feasible) design: ``objectives``, ``status``, ``runs``; runs what is new."""
        todo: dict[str, Checked] = {}
        for design in designs:
            if design.id not in self.stored and design.id not in todo:
                todo[design.id] = self.check(design)
        if todo:
            self._evaluate_new(list(todo.values()))
        return [self.stored[d.id] for d in designs]

    def _entry(self, checked: Checked, runs: dict[str, dict]) -> dict:
        failed = [f"{label} run: {r['error']}" for label, r in runs.items() if r["status"] != "success"]
        objectives = objective_values(self.problem.objectives, checked.ideal,
                                      {label: r["metrics"] for label, r in runs.items() if r["status"] == "success"})
        missing = [name for name, value in objectives.items() if value is None]
        if missing and not failed:
            failed.append(f"no value for {', '.join(missing)}")
        return {"id": checked.design.id, "values": list(checked.design.values), "objectives": objectives,
                "status": "failed" if failed else "success", "error": "; ".join(failed),
                "runs": {label: {"status": r["status"], "metrics": r["metrics"], "wall_time_s": r["wall_time_s"]}
                         for label, r in runs.items()}}

    def _store(self, entry: dict) -> None:
        self.log.append(entry)
        self.stored[entry["id"]] = normalise(entry)
        self.run_count += 1
        if self.on_evaluated is not None:
            self.on_evaluated(entry)

    def _evaluate_new(self, todo: list[Checked]) -> None:
        if not self.runs:
            for checked in todo:
                self._store(self._entry(checked, {}))
            return
        pending: dict[str, dict] = {c.design.id: {} for c in todo}
        by_id = {c.design.id: c for c in todo}
        futures: dict[cf.Future, tuple[str, str]] = {}
        pool = self._pool(len(todo) * len(self.runs))
        for checked in todo:
            for label, keys in self.run_scenes(checked).items():
                futures[pool.submit(solve_design, label, keys, self.problem.engine)] = (checked.design.id, label)
        lost: set[str] = set()
        for future in cf.as_completed(futures):
            design_id, label = futures[future]
            try:
                outcome = future.result()
            except Exception as exc:  # noqa: BLE001 - a worker that died, an unpicklable result, a dask KilledWorker
                outcome = {"status": "failed", "error": f"{type(exc).__name__}: {exc}", "metrics": {},
                           "wall_time_s": float("nan")}
                lost.add(design_id)
            pending[design_id][label] = outcome
            if len(pending[design_id]) == len(self.runs):
                entry = self._entry(by_id[design_id], pending.pop(design_id))
                if design_id in lost:  # not the design's fault: kept for this run only, run again on a resume
                    self.stored[design_id] = normalise(entry)
                    log.warning("design %s lost with its worker: %s", design_id, entry["error"])
                else:
                    self._store(entry)
        if lost and self.stop_pool is not None:  # a broken local pool is replaced for the next batch
            self.stop_pool(False)
            self.pool = self.stop_pool = None

    def _pool(self, n: int):
        if self.pool is None:
            from weftsim.sweep.pool import executor

            self.pool, _, self.stop_pool = executor(self.jobs, self.scheduler, max(n, 1), self.problem.engine)
        return self.pool

    def close(self, interrupted: bool = False) -> None:
        if self.stop_pool is not None:
            self.stop_pool(interrupted)
            self.pool = self.stop_pool = None
        self.log.close()
