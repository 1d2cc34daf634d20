"""One sweep at a time in a sweep directory: ``sweep.lock``, naming its holder.

Two sweeps writing one directory at once would compute shared cells twice and leave a
``sweep.json`` listing combinations neither ran.  The first takes the lock by creating
``sweep.lock`` exclusively (``O_CREAT | O_EXCL``, atomic on a local file system and on
NFSv3+), holding the holder's host, process id, boot id and start time; the second is
refused with those.  The lock is removed when the sweep ends, however it ends short of
SIGKILL or a power cut.  A lock left behind is *stale* when its holder ran on this host
and is no longer running (its process id is gone, or the machine has rebooted since:
another boot id); the next sweep then takes it over and says so.  A lock from another
host cannot be checked from here and is never taken over.
"""

from __future__ import annotations

import datetime
import json
import logging
import os
import socket
from pathlib import Path

from weftsim.sweep.grid import SweepError

LOCK_FILE = "sweep.lock"
BOOT_ID = Path("/proc/sys/kernel/random/boot_id")  # Linux; elsewhere only the process id is checked

log = logging.getLogger(__name__)


def _boot_id() -> str | None:
    try:
        return BOOT_ID.read_text().strip()
    except OSError:
        return None


def _holder() -> dict:
    return {"host": socket.gethostname(), "pid": os.getpid(), "boot_id": _boot_id(),
            "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def _describe(holder: dict) -> str:
    return f"process {holder.get('pid')} on host {holder.get('host')}, started {holder.get('started')} UTC"


def _running(holder: dict) -> bool | None:
    """True/False for a holder on this host; None when it cannot be told from here (another host)."""
    if holder.get("host") != socket.gethostname():
        return None
    if holder.get("boot_id") and _boot_id() and holder["boot_id"] != _boot_id():
        return False  # the machine has rebooted since: no process of before runs now
    pid = holder.get("pid")
    if isinstance(pid, bool) or not isinstance(pid, int) or not 0 < pid < 2**31:  # no process has another id
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # a process of another user holds that id
    return True


class SweepLock:
    """Context manager holding ``DIR/sweep.lock`` for the length of a sweep."""

    def __init__(self, outdir: str | Path):
        self.path = Path(outdir) / LOCK_FILE
        self.held = False

    def _create(self) -> bool:
        try:
            fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            return False
        except OSError as exc:
            raise SweepError(f"cannot create the sweep lock {self.path}: {exc.strerror}") from None
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(_holder(), f)
        return True

    def _read(self) -> dict:
        try:
            holder = json.loads(self.path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return {}
        except (OSError, ValueError, RecursionError):
            holder = None
        return holder if isinstance(holder, dict) else {"damaged": True}

    def acquire(self) -> None:
        """Take the lock, taking over a stale one; SweepError naming the holder of a live one."""
        for _ in range(3):  # a lock removed or taken over between our two looks: look again
            if self._create():
                self.held = True
                return
            holder = self._read()
            if not holder:
                continue
            if holder.get("damaged"):
                raise SweepError(f"{self.path} is not a lock weftsim can read (damaged, or a directory); if no sweep "
                                 f"runs in {self.path.parent}, delete it and run again")
            running = _running(holder)
            if running is False:
                # Rename first: of two sweeps taking over the same stale lock, only one rename succeeds.
                stale = self.path.with_name(f".{LOCK_FILE}.stale-{os.getpid()}")
                try:
                    os.replace(self.path, stale)
                except FileNotFoundError:
                    continue
                stale.unlink(missing_ok=True)
                log.warning("taking over the stale sweep lock %s of %s, which is no longer running",
                            self.path, _describe(holder))
                continue
            unknown = " (another host: weftsim cannot tell whether it still runs)" if running is None else ""
            raise SweepError(f"sweep directory {self.path.parent} is in use by {_describe(holder)}{unknown}; "
                             f"wait for it to end, or delete {self.path} if that sweep is gone")
        raise SweepError(f"cannot take the sweep lock {self.path}: it keeps changing hands")

    def release(self) -> None:
        if self.held and self._read().get("pid") == os.getpid():  # never remove a lock another sweep holds
            self.path.unlink(missing_ok=True)
        self.held = False

    def __enter__(self) -> SweepLock:
        self.acquire()
        return self

    def __exit__(self, *exc) -> None:
        self.release()
