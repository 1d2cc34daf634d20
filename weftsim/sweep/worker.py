"""The local pool's worker processes: started once, run many cells, die with the sweep.

Each worker is started once per sweep and runs cell after cell, so the engine's import, its
compiled code and its numba cache are loaded once per worker, not once per cell.  A worker
must not outlive the sweep process that started it: if that process is killed (SIGKILL, or a
SIGTERM that finds it blocked), an orphaned worker would finish its cell and then wait forever
for work, and could race a resumed sweep writing the same cell.  On Linux the kernel sends the
worker SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``, see ``man 2 prctl``); a
watchdog thread that compares the parent process id once a second covers other systems.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import threading
import time

PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>
WATCH_INTERVAL_S = 1.0  # how often the watchdog looks at the parent (the fallback where prctl is missing)


def _kernel_kills_orphan() -> bool:
    """Ask Linux to SIGKILL this process when its parent dies; False where that is not available."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError, TypeError):
        return False


def _watch_parent(parent_pid: int) -> None:
    while True:
        time.sleep(WATCH_INTERVAL_S)
        if os.getppid() != parent_pid:
            os._exit(1)  # orphaned: the sweep is gone, its cell is unfinished and will rerun


def die_with_parent(parent_pid: int) -> None:
    """End this process when ``parent_pid`` (the sweep) ends, however it ends."""
    _kernel_kills_orphan()
    if os.getppid() != parent_pid:  # the parent died before the request above took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="weftsim-watch-parent").start()


def start_worker(parent_pid: int, engine: str) -> None:
    """Pool initializer: tie the worker to the sweep, then import the engine once for all its cells.

    An engine that fails to import is not an error here (it would break the whole pool): the
    first cell reports it as that cell's failure.
    """
    die_with_parent(parent_pid)
    from weftsim.sweep.engines import engine_solve

    try:
        engine_solve(engine)
    except Exception:  # noqa: BLE001 - reported by the cell that needs it (failures are not cached)
        pass
