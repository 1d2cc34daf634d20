"""Where a sweep's cells run: a local process pool or a Dask cluster; and the progress line.

Both run :func:`weftsim.sweep.cell.solve_cell` with plain data and send the outcome back to
the sweep's process, which alone writes the sweep directory.  A Dask worker therefore needs
weftsim installed, but neither the scene file nor the sweep directory: it may run in another
working directory, on another machine, without a shared file system.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
import sys
import time
from typing import Callable

from weftsim.checks.progress import RateEstimate
from weftsim.sweep.grid import SweepError

MANAGER_JOIN_S = 10.0  # s: the manager thread ends within ms of its workers' death
CONNECT_TIMEOUT_S = 20.0  # how long to keep trying to reach a Dask scheduler (it may be starting up)


def executor(jobs: int | None, scheduler: str | None, n_cells: int, engine: str) -> tuple[cf.Executor, int, Callable[..., None]]:
    """(executor, in-flight window, stop): a local process pool, or a Dask client's executor.

    ``stop(interrupted)`` cancels what has not started and returns without waiting for running
    cells; after an interrupt it also ends the local workers.
    """
    if scheduler:
        return _dask_executor(scheduler)
    from weftsim.sweep.worker import start_worker

    workers = max(1, min(jobs or os.cpu_count() or 1, n_cells))
    pool = cf.ProcessPoolExecutor(max_workers=workers, initializer=start_worker, initargs=(os.getpid(), engine))

    def stop_pool(interrupted: bool = False) -> None:
        # On an interrupt the workers may already hold the next queued cells (the pool hands each
        # worker one ahead), and Python's exit would wait for them: end them, their cells are
        # unfinished and will rerun, and every finished cell is already on disk.
        workers_alive = list((getattr(pool, "_processes", None) or {}).values()) if interrupted else []
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers_alive:
            process.kill()
        if interrupted:
            # Let the pool's manager thread see its killed workers and close its wake-up pipe now: left running, it
            # closes the pipe while Python's exit writes to it (CPython 3.11's concurrent.futures checks the pipe
            # and writes without a lock), and the exit prints "OSError: Bad file descriptor" with a traceback
            # after the sweep's one line (seen in about 1 run in 12 of the SIGTERM test on 2 busy cores).
            manager = getattr(pool, "_executor_manager_thread", None)
            if manager is not None:
                manager.join(timeout=MANAGER_JOIN_S)

    return pool, workers, stop_pool


def _dask_executor(scheduler: str):
    try:
        from dask.distributed import Client
    except ImportError:
        raise SweepError("--scheduler needs dask.distributed: pip install 'weftsim[distributed]'") from None
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepError(f"--scheduler: cannot reach the Dask scheduler at {scheduler} ({exc})") from None
    threads = sum(client.nthreads().values()) or 1
    dask_executor = client.get_executor(pure=False)

    def stop_dask(interrupted: bool = False) -> None:
        dask_executor.shutdown(wait=False)  # cancels the cells still on the cluster
        client.close()

    return dask_executor, threads * 2, stop_dask  # a short queue per worker keeps them busy


class SweepProgress:
    """Cells done, failed and time left on stderr: one refreshed line on a terminal, else every ``interval`` s.

    ``what`` and ``unit`` name the command and what it counts (``weftsim optimize`` counts designs evaluated).
    """

    def __init__(self, total: int, skipped: int, stream=None, interval: float = 1.0,
                 clock: Callable[[], float] = time.perf_counter, what: str = "sweep", unit: str = "cells"):
        self.total, self.skipped = total, skipped
        self.what, self.unit = what, unit
        self.stream = stream if stream is not None else sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.interval = interval if self.tty else max(interval, 10.0)
        self.clock = clock
        self.start = clock()
        # The first cells carry the workers' start-up (a process, the imports, numba's compilation):
        # the rate is measured from the first cell done on (settle 0: a cell marks the end of it).
        self.rate = RateEstimate(self.start, settle=0.0)
        self.rate_started = False
        self.last = float("-inf")

    def update(self, done: int, failed: int, final: bool = False) -> None:
        now = self.clock()
        run = self.total - self.skipped
        if done and not self.rate_started:  # the first cell done: the start-up is behind
            self.rate = RateEstimate(now, settle=0.0)
            self.rate_started = True
        if self.rate_started:
            self.rate.add(now, done / max(run, 1))
        if not final and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.start
        left = self.rate.left(now, done / max(run, 1)) if self.rate_started else float("nan")
        shown = f", left ~{left:.0f} s" if math.isfinite(left) else ", left: measuring"
        text = (f"{self.what}: {done}/{run} {self.unit}" + (" done" if self.unit == "cells" else "")
                + f", {failed} failed"
                + (f", {self.skipped} already finished" if self.skipped else "")
                + f", elapsed {elapsed:.0f} s" + ("" if final else shown))
        self.stream.write(("\r" + text + ("\n" if final else "")) if self.tty else text + "\n")
        self.stream.flush()
