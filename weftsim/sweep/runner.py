"""Design sweeps: run a grid of scene variants in parallel, resumably, and tabulate their peaks.

``weftsim sweep SCENE --vary KEY=VALUES ...`` is :func:`plan_sweep` then :func:`run_sweep`:

1. plan: parse the grid (:mod:`weftsim.sweep.grid`), build and validate the scene of
   EVERY cell with :func:`weftsim.scene.load_scene` before anything runs, and check the
   output directory holds no other sweep (:mod:`weftsim.sweep.store`);
2. run: skip the cells already finished, send the others to a local process pool
   (default, ``--jobs`` workers) or to an existing Dask cluster (``--scheduler``), each
   as :func:`weftsim.sweep.cell.run_cell` in its own process; a failed cell is recorded
   and the others go on; a worker that dies is retried once, alone;
3. tabulate: ``sweep.csv`` is rebuilt from the cell directories (periodically, at the
   end and on interrupt) and ``sweep.png`` drawn for 1-D and 2-D grids.

See docs/sweeps.md.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import logging
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from weftsim.sweep.cell import cell_record, is_finished, normalise, resolve_engine, run_cell, write_cell_record
from weftsim.sweep.grid import Axis, Cell, SweepError, grid_cells, parse_set, parse_vary
from weftsim.sweep.store import (SWEEP_FILE, TABLE_FILE, collect_rows, manifest, merge_manifest, table_text)

log = logging.getLogger(__name__)

FIGURE_FILE = "sweep.png"
TABLE_INTERVAL_S = 10.0  # rewrite sweep.csv at most this often while cells complete
CONNECT_TIMEOUT_S = 20.0  # how long to keep trying to reach a Dask scheduler (it may be starting up)
DEATHS_BEFORE_FAILED = 2  # a cell whose worker died this often (the second time alone) is recorded as failed


@dataclass(frozen=True)
class PlannedCell:
    """A cell with everything a worker needs (plain data) and the expected scene keys."""

    cell: Cell
    overrides: dict
    scene_keys: dict


@dataclass(frozen=True)
class SweepPlan:
    """A validated sweep: base scene, grid and the planned cells (nothing run, nothing written)."""

    scene_path: str
    engine: str
    axes: tuple[Axis, ...]
    fixed: dict
    base_keys: dict
    cells: tuple[PlannedCell, ...]

    @property
    def axis_names(self) -> list[str]:
        return [axis.name for axis in self.axes]


def plan_sweep(scene_path: str | Path, vary: list[str], fixed: list[str] | tuple = (),
               engine: str = "reference") -> SweepPlan:
    """Parse ``--vary``/``--set`` texts and validate the scene of every cell.

    Raises
    ------
    SweepError
        Bad grid text or engine, or any cell whose scene is invalid (all such cells are named).
    weftsim.scene.SceneError
        The base scene itself is invalid.
    """
    from weftsim.scene import SceneError, load_scene, to_file_keys

    axes = tuple(parse_vary(text) for text in vary)
    fixed_overrides = dict(parse_set(text) for text in fixed)
    cells = grid_cells(axes, fixed_overrides)
    try:
        resolve_engine(engine)
    except (ValueError, ImportError, AttributeError) as exc:
        raise SweepError(f"--engine: cannot use {engine!r} ({exc})") from None
    base = load_scene(scene_path, fixed_overrides)
    planned, problems = [], {}
    for cell in cells:
        overrides = {**cell.overrides, "name": f"{base.name}[{cell.name}]"}
        try:
            scene = load_scene(scene_path, overrides)
        except SceneError as exc:
            problems.setdefault(str(exc), []).append(cell.name)
            continue
        planned.append(PlannedCell(cell, overrides, normalise(to_file_keys(scene))))
    if problems:
        lines = [f"{message} (cell{'s' if len(names) > 1 else ''} {', '.join(names[:3])}"
                 f"{f' and {len(names) - 3} more' if len(names) > 3 else ''})" for message, names in problems.items()]
        bad = sum(len(n) for n in problems.values())
        raise SweepError(f"{bad} of {len(cells)} cells are invalid, nothing was run: " + "; ".join(lines))
    return SweepPlan(str(scene_path), engine, axes, fixed_overrides, normalise(to_file_keys(base)), tuple(planned))


@dataclass
class SweepReport:
    """What a sweep did: counts, time, written files and the table rows."""

    outdir: Path
    total: int
    skipped: int = 0
    succeeded: int = 0
    failed: int = 0
    wall_time_s: float = 0.0
    table: Path | None = None
    figure: Path | None = None
    rows: list[dict] = field(default_factory=list)
    failures: dict[str, str] = field(default_factory=dict)


class SweepProgress:
    """Cells done, failed and time left on stderr: one refreshed line on a terminal, else every ``interval`` s."""

    def __init__(self, total: int, skipped: int, stream=None, interval: float = 1.0):
        self.total, self.skipped = total, skipped
        self.stream = stream if stream is not None else sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.interval = interval if self.tty else max(interval, 10.0)
        self.start = time.perf_counter()
        self.last = float("-inf")

    def update(self, done: int, failed: int, final: bool = False) -> None:
        now = time.perf_counter()
        if not final and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.start
        run = self.total - self.skipped
        left = elapsed * (run - done) / done if done else float("nan")
        text = (f"sweep: {done}/{run} cells done, {failed} failed"
                + (f", {self.skipped} already finished" if self.skipped else "")
                + f", elapsed {elapsed:.0f} s" + ("" if final else f", left ~{left:.0f} s"))
        self.stream.write(("\r" + text + ("\n" if final else "")) if self.tty else text + "\n")
        self.stream.flush()


def _executor(jobs: int | None, scheduler: str | None, n_cells: int):
    """(executor, in-flight window, stop): a local process pool, or a Dask client's executor.

    ``stop(interrupted)`` cancels what has not started and returns without waiting for running
    cells; after an interrupt it also ends the local workers.
    """
    if scheduler:
        try:
            from dask.distributed import Client
        except ImportError:
            raise SweepError("--scheduler needs dask.distributed: pip install 'weftsim[distributed]'") from None
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as exc:
            raise SweepError(f"--scheduler: cannot reach the Dask scheduler at {scheduler} ({exc})") from None
        threads = sum(client.nthreads().values()) or 1
        executor = client.get_executor(pure=False)

        def stop_dask(interrupted: bool = False) -> None:
            executor.shutdown(wait=False)  # cancels the cells still on the cluster
            client.close()

        return executor, threads * 2, stop_dask  # a short queue per worker keeps them busy
    workers = max(1, min(jobs or os.cpu_count() or 1, n_cells))
    pool = cf.ProcessPoolExecutor(max_workers=workers)

    def stop_pool(interrupted: bool = False) -> None:
        # On an interrupt the workers may already hold the next queued cells (the pool hands each
        # worker one ahead), and Python's exit would wait for them: end them, their cells are
        # unfinished and will rerun, and every finished cell is already on disk.
        workers_alive = list((getattr(pool, "_processes", None) or {}).values()) if interrupted else []
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers_alive:
            process.kill()

    return pool, workers, stop_pool


def _record_lost(outdir: Path, planned: PlannedCell, engine: str, error: str) -> dict:
    """Record a cell whose worker never returned (crash, killed worker) from the driver."""
    record = cell_record(planned.cell.name, planned.cell.params, planned.overrides, planned.scene_keys, engine,
                         "failed", error, float("nan"), None)
    directory = outdir / planned.cell.name
    directory.mkdir(parents=True, exist_ok=True)
    write_cell_record(directory, record)
    return record


def write_table(plan: SweepPlan, outdir: Path, pending: list[PlannedCell] = ()) -> tuple[Path, list[dict]]:
    """Rebuild ``sweep.csv`` from the cell directories (cells not yet run listed as pending)."""
    from weftsim.output import write_text

    rows = collect_rows(outdir, plan.axis_names, {p.cell.name: p.cell.params for p in pending})
    return write_text(outdir / TABLE_FILE, table_text(rows, plan.axis_names)), rows


def write_figure(plan: SweepPlan, outdir: Path, rows: list[dict]) -> Path | None:
    """``sweep.png`` for 1-D and 2-D sweeps (None for more axes or no successful cell)."""
    from weftsim.output import write_figure as save
    from weftsim.sweep.plots import plot_sweep

    base = plan.base_keys
    title = (f"{Path(plan.scene_path).name}, {plan.engine} engine, {base['joint_e.law']}, "
             f"{base['drive.revolutions']:g} revolutions: largest magnitude over a crank revolution")
    figure = plot_sweep(rows, plan.axis_names, title)
    return save(outdir / FIGURE_FILE, figure) if figure is not None else None


def run_sweep(plan: SweepPlan, outdir: str | Path, jobs: int | None = None, scheduler: str | None = None,
              cell_figures: bool = False, progress: bool = True, stream=None) -> SweepReport:
    """Run every unfinished cell of ``plan`` into ``outdir`` and write the table and figure.

    Parameters
    ----------
    plan : SweepPlan
        From :func:`plan_sweep`.
    outdir : str or Path
        Sweep directory; may hold this sweep already (finished cells are skipped).
    jobs : int, optional
        Local worker processes (default ``os.cpu_count()``); ignored with ``scheduler``.
    scheduler : str, optional
        Address of a running Dask scheduler, e.g. ``tcp://127.0.0.1:8786``.  Workers need
        weftsim installed and ``outdir`` and the scene file at the same paths.
    cell_figures : bool
        Also draw each cell's ``channels.png`` (slower).
    progress : bool
        Report cells done, failed and time left on ``stream`` (stderr).

    Raises
    ------
    SweepError
        ``outdir`` holds a different sweep, or the scheduler cannot be reached.
    KeyboardInterrupt
        After cancelling the queued cells and rewriting the table (finished cells stay).
    """
    from weftsim.output import prepare_directory, write_json

    outdir = Path(outdir)
    data = merge_manifest(outdir, manifest(plan.scene_path, plan.base_keys, plan.fixed, plan.engine,
                                           list(plan.axes)))
    prepare_directory(outdir, force=True)  # merge_manifest has refused foreign directories already
    write_json(outdir / SWEEP_FILE, data)
    start = time.perf_counter()
    todo = [p for p in plan.cells if not is_finished(outdir / p.cell.name, p.scene_keys, plan.engine)]
    report = SweepReport(outdir, len(plan.cells), skipped=len(plan.cells) - len(todo))
    log.info("sweep %s: %d cells, %d already finished", outdir, report.total, report.skipped)
    bar = SweepProgress(report.total, report.skipped, stream) if progress else None
    remaining = list(todo)
    try:
        if todo:
            _run_cells(plan, outdir, todo, remaining, report, jobs, scheduler, cell_figures, bar)
    except KeyboardInterrupt:
        write_table(plan, outdir, remaining)
        raise
    report.wall_time_s = time.perf_counter() - start
    if bar:
        bar.update(report.succeeded + report.failed, report.failed, final=True)
    report.table, report.rows = write_table(plan, outdir)
    report.figure = write_figure(plan, outdir, report.rows)
    return report


def _run_cells(plan, outdir, todo, remaining, report, jobs, scheduler, cell_figures, bar) -> None:
    """The scheduling loop: keep ``window`` cells in flight; a dead local pool is replaced."""
    queue = collections.deque(todo)
    retry: collections.deque = collections.deque()  # cells whose worker died: rerun one at a time
    deaths: collections.Counter = collections.Counter()
    executor, window, stop = _executor(jobs, scheduler, len(todo))
    in_flight: dict[cf.Future, PlannedCell] = {}
    last_table = time.perf_counter()

    def submit(planned: PlannedCell):
        future = executor.submit(run_cell, plan.scene_path, planned.overrides, planned.cell.params,
                                 str(outdir / planned.cell.name), plan.engine, cell_figures)
        in_flight[future] = planned

    def finish(planned: PlannedCell, record: dict) -> None:
        remaining.remove(planned)
        if record["status"] == "success":
            report.succeeded += 1
        else:
            report.failed += 1
            report.failures[planned.cell.name] = record["error"]
            log.warning("sweep cell %s failed: %s", planned.cell.name, record["error"])

    interrupted = True
    try:
        while queue or retry or in_flight:
            broken = False
            try:
                if retry:
                    if not in_flight:
                        submit(retry[0])
                        retry.popleft()
                else:
                    while queue and len(in_flight) < window:
                        submit(queue[0])
                        queue.popleft()
            except cf.process.BrokenProcessPool:
                broken = True  # the pool broke before its futures said so: replaced below, the cell stays queued
            done, _ = cf.wait(in_flight, return_when=cf.FIRST_COMPLETED) if in_flight else (set(), set())
            for future in done:
                planned = in_flight.pop(future)
                try:
                    finish(planned, future.result())
                except cf.process.BrokenProcessPool:
                    broken = True
                    deaths[planned.cell.name] += 1
                    if deaths[planned.cell.name] >= DEATHS_BEFORE_FAILED:
                        finish(planned, _record_lost(outdir, planned, plan.engine,
                                                     "the worker process died while running this cell "
                                                     f"({deaths[planned.cell.name]} times, the last time alone): "
                                                     "crash, out of memory or killed"))
                    else:
                        retry.append(planned)
                except Exception as exc:  # e.g. dask KilledWorker, or an unpicklable result
                    finish(planned, _record_lost(outdir, planned, plan.engine, f"{type(exc).__name__}: {exc}"))
            if broken:
                for future, planned in list(in_flight.items()):
                    retry.append(planned)  # lost with the pool without being to blame
                    in_flight.pop(future)
                stop()
                executor, window, stop = _executor(jobs, scheduler, len(remaining))
            if bar:
                bar.update(report.succeeded + report.failed, report.failed)
            if time.perf_counter() - last_table > TABLE_INTERVAL_S:
                write_table(plan, outdir, remaining)
                last_table = time.perf_counter()
        interrupted = False
    finally:
        stop(interrupted)


def format_report(report: SweepReport) -> str:
    """A few lines for the command line."""
    lines = [f"sweep {report.outdir}: {report.total} cells, {report.skipped} already finished, "
             f"{report.succeeded} succeeded, {report.failed} failed, {report.wall_time_s:.1f} s wall time"]
    for name, error in list(report.failures.items())[:10]:
        lines.append(f"  failed {name}: {error.splitlines()[0] if error else ''}")
    if len(report.failures) > 10:
        lines.append(f"  ... and {len(report.failures) - 10} more failed cells (see the table)")
    lines.append(f"  wrote {report.table}")
    if report.figure:
        lines.append(f"  wrote {report.figure}")
    return "\n".join(lines)
