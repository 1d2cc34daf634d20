"""Design sweeps: run a grid of scene variants in parallel, resumably, and tabulate their peaks.

``weftsim sweep SCENE --vary KEY=VALUES ...`` is :func:`~weftsim.sweep.plan.plan_sweep` then :func:`run_sweep`:

1. plan: parse the grid (:mod:`weftsim.sweep.grid`), check the engine and validate the
   scene of EVERY cell before anything runs (:mod:`weftsim.sweep.plan`);
2. run: take the directory's lock (:mod:`weftsim.sweep.lock`), check it holds no other
   sweep (:mod:`weftsim.sweep.store`), skip the cells already finished, and send each of
   the others, as its resolved scene (data), to a local process pool (default, ``--jobs``
   workers) or to an existing Dask cluster (``--scheduler``) (:mod:`weftsim.sweep.pool`).
   Each outcome comes back to this process, which writes the cell
   (:func:`weftsim.sweep.cell.store_cell`) as soon as it arrives; a failed cell is
   recorded and the others go on; a worker that dies is retried once, alone;
3. tabulate: ``sweep.csv`` is rebuilt from the cell directories (periodically, at the
   end and on interrupt) and ``sweep.png`` drawn for 1-D and 2-D grids.

See docs/sweeps.md.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from weftsim.post.record import command_line
from weftsim.sweep.cell import CELL_FILE, cell_record, is_finished, solve_cell, store_cell, write_cell_record
from weftsim.sweep.grid import SweepError
from weftsim.sweep.lock import SweepLock
from weftsim.sweep.plan import PlannedCell, SweepPlan
from weftsim.sweep.pool import SweepProgress, executor
from weftsim.sweep.store import SWEEP_FILE, TABLE_FILE, collect_rows, manifest, merge_manifest, table_text

if TYPE_CHECKING:
    from typing import TextIO

log = logging.getLogger(__name__)

FIGURE_FILE = "sweep.png"
TABLE_INTERVAL_S = 10.0  # rewrite sweep.csv at most this often while cells complete
DEATHS_BEFORE_FAILED = 2  # a cell whose worker died this often (the second time alone) is recorded as failed


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


def _record_lost(outdir: Path, plan: SweepPlan, planned: PlannedCell, scene_keys: dict, error: str) -> dict:
    """Record a cell whose worker never returned (crash, killed worker) from the driver."""
    record = cell_record(planned.cell.name, planned.cell.params, planned.overrides, scene_keys, plan.engine,
                         "failed", error, float("nan"), None)
    directory = outdir / planned.cell.name
    directory.mkdir(parents=True, exist_ok=True)
    write_cell_record(directory, record)
    return record


def write_table(plan: SweepPlan, outdir: Path, pending: dict[str, PlannedCell] | None = None
                ) -> tuple[Path, list[dict]]:
    """Rebuild ``sweep.csv`` from the cell directories (``pending``: cells not yet run, by name)."""
    from weftsim.post.output import write_text

    rows = collect_rows(outdir, plan.axis_names, {n: p.cell.params for n, p in (pending or {}).items()})
    return write_text(outdir / TABLE_FILE, table_text(rows, plan.axis_names)), rows


def write_figure(plan: SweepPlan, outdir: Path, rows: list[dict]) -> Path | None:
    """``sweep.png`` for 1-D and 2-D sweeps (None for more axes or no successful cell)."""
    from weftsim.post.output import write_figure as save
    from weftsim.sweep.plots import plot_sweep

    base = plan.base_keys
    varied = {axis.key for axis in plan.axes}
    laws = [f"{base[f'joint_{j}.law']} at {j.upper()}" for j in ("e", "f")  # the laws of the joints with a clearance
            if (base.get(f"joint_{j}.clearance_mm") or 0) > 0 or f"joint_{j}.clearance_mm" in varied]
    title = (f"{Path(plan.scene_path).name}, {plan.engine} engine, {', '.join(laws) or 'ideal joints'}, "
             f"{base['drive.revolutions']:g} revolutions: largest magnitude over a crank revolution")
    figure = plot_sweep(rows, plan.axis_names, title)
    return save(outdir / FIGURE_FILE, figure) if figure is not None else None


def _open_directory(outdir: Path, plan: SweepPlan, lock: SweepLock) -> None:
    """Check ``outdir`` can take this sweep, create it, lock it and write ``sweep.json`` (union of the grids)."""
    from weftsim.post.output import OutputError, prepare_directory, write_json

    if outdir.exists() and not outdir.is_dir():
        raise SweepError(f"sweep directory {outdir} exists and is not a directory; choose another -o")
    new = manifest(plan.scene_path, plan.base_keys, plan.fixed, plan.engine, list(plan.axes))
    merge_manifest(outdir, new)  # refuses a foreign directory before anything is created in it
    try:
        prepare_directory(outdir, force=True)  # merge_manifest has refused foreign directories already
    except OutputError as exc:
        raise SweepError(str(exc)) from None
    lock.acquire()
    write_json(outdir / SWEEP_FILE, merge_manifest(outdir, new))  # again under the lock: another sweep may have been first
    from weftsim.post.output import check_file_target

    for name in (TABLE_FILE, FIGURE_FILE):  # before any cell runs: the table and figure come last
        if (outdir / name).is_dir():
            raise SweepError(f"{outdir / name} is a directory, where the sweep writes its {name}; remove it to run "
                             "the sweep there")
        try:
            check_file_target(outdir / name)
        except OutputError as exc:
            raise SweepError(str(exc)) from None


def run_sweep(plan: SweepPlan, outdir: str | Path, jobs: int | None = None, scheduler: str | None = None,
              cell_figures: bool = False, progress: bool = True, stream: TextIO | None = None) -> SweepReport:
    """Run every unfinished cell of ``plan`` into ``outdir`` and write the table and figure.

    Parameters
    ----------
    plan : SweepPlan
        From :func:`~weftsim.sweep.plan.plan_sweep`.
    outdir : str or Path
        Sweep directory; may hold this sweep already (finished cells are skipped).  Only this
        process reads and writes it, under its lock ``sweep.lock``.
    jobs : int, optional
        Local worker processes (default ``os.cpu_count()``); ignored with ``scheduler``.
    scheduler : str, optional
        Address of a running Dask scheduler, e.g. ``tcp://127.0.0.1:8786``.  Workers need
        weftsim installed, not the scene file or ``outdir``: each cell goes out as data and its
        files come back.
    cell_figures : bool
        Also draw each cell's ``channels.png`` (slower).
    progress : bool
        Report cells done, failed and time left on ``stream`` (stderr).

    Raises
    ------
    SweepError
        ``outdir`` is a file, holds a different sweep or is locked by a running sweep; the
        scheduler cannot be reached; a cell's files cannot be written.
    KeyboardInterrupt
        After cancelling the queued cells and rewriting the table (finished cells stay).
    """
    outdir = Path(outdir)
    lock = SweepLock(outdir)
    try:
        _open_directory(outdir, plan, lock)
        start = time.perf_counter()
        todo = [p for p in plan.cells if not _finished(plan, outdir, p)]
        keys: dict[str, dict] = {}  # each cell's resolved scene, built when the cell is sent
        report = SweepReport(outdir, len(plan.cells), skipped=len(plan.cells) - len(todo))
        log.info("sweep %s: %d cells, %d already finished", outdir, report.total, report.skipped)
        bar = SweepProgress(report.total, report.skipped, stream) if progress else None
        remaining = {p.cell.name: p for p in todo}
        try:
            if todo:
                _run_cells(plan, outdir, todo, keys, remaining, report, jobs, scheduler, cell_figures, bar)
        except KeyboardInterrupt:
            write_table(plan, outdir, remaining)
            raise
        report.wall_time_s = time.perf_counter() - start
        if bar:
            bar.update(report.succeeded + report.failed, report.failed, final=True)
        report.table, report.rows = write_table(plan, outdir)
        report.figure = write_figure(plan, outdir, report.rows)
        return report
    finally:
        lock.release()


def _finished(plan: SweepPlan, outdir: Path, planned: PlannedCell) -> bool:
    """True if the cell is finished on disk; its scene is rebuilt only where there is a record to compare."""
    cell_dir = outdir / planned.cell.name
    return (cell_dir / CELL_FILE).is_file() and is_finished(cell_dir, plan.scene_keys(planned), plan.engine)


def _store(outdir: Path, plan: SweepPlan, planned: PlannedCell, scene_keys: dict, outcome: dict) -> dict:
    """Write a returned cell into the sweep directory (this process alone writes it)."""
    record = cell_record(planned.cell.name, planned.cell.params, planned.overrides, scene_keys, plan.engine,
                         outcome["status"], outcome["error"], outcome["wall_time_s"], outcome["metrics"],
                         outcome.get("worker"))
    try:
        store_cell(outdir / planned.cell.name, record, outcome["files"], outcome["detail"])
    except OSError as exc:
        raise SweepError(f"cannot write cell {planned.cell.name} into {outdir}: {exc.strerror or exc}; "
                         "the cells written before it are kept, rerun to resume") from None
    return record


def _run_cells(plan, outdir, todo, keys, remaining, report, jobs, scheduler, cell_figures, bar) -> None:
    """The scheduling loop: keep ``window`` cells in flight; a dead local pool is replaced."""
    queue = collections.deque(todo)
    retry: collections.deque = collections.deque()  # cells whose worker died: rerun one at a time
    deaths: collections.Counter = collections.Counter()
    pool, window, stop = executor(jobs, scheduler, len(todo), plan.engine)
    in_flight: dict[cf.Future, PlannedCell] = {}
    last_table = time.perf_counter()
    command = command_line()  # the sweep's, recorded in every cell (a worker's own arguments say nothing)

    def submit(planned: PlannedCell):
        name = planned.cell.name
        if name not in keys:
            keys[name] = plan.scene_keys(planned)
        # The resolved scene travels, not the file's path: the stored keys without the absent optional ones.
        data = {key: value for key, value in keys[name].items() if value is not None}
        in_flight[pool.submit(solve_cell, name, data, plan.engine, cell_figures, command)] = planned

    def finish(planned: PlannedCell, record: dict) -> None:
        del remaining[planned.cell.name]
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
                name = planned.cell.name
                try:
                    outcome = future.result()
                except cf.process.BrokenProcessPool:
                    broken = True
                    deaths[name] += 1
                    if deaths[name] >= DEATHS_BEFORE_FAILED:
                        finish(planned, _record_lost(outdir, plan, planned, keys[name],
                                                     "the worker process died while running this cell "
                                                     f"({deaths[name]} times, the last time alone): "
                                                     "crash, out of memory or killed"))
                    else:
                        retry.append(planned)
                    continue
                except Exception as exc:  # e.g. dask KilledWorker, or an unpicklable result
                    finish(planned, _record_lost(outdir, plan, planned, keys[name], f"{type(exc).__name__}: {exc}"))
                    continue
                finish(planned, _store(outdir, plan, planned, keys[name], outcome))
            if broken:
                for future, planned in list(in_flight.items()):
                    retry.append(planned)  # lost with the pool without being to blame
                    in_flight.pop(future)
                stop()
                pool, window, stop = executor(jobs, scheduler, len(remaining), plan.engine)
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
