"""Signals that end a pooled command (``weftsim sweep``, a wear ensemble) as Ctrl-C does.

SIGTERM (``kill``, a batch scheduler at its time limit, a container stop) and SIGHUP (the terminal went
away) would end the process without a word and leave the pool's workers running; within
:func:`terminated_as_interrupt` they raise :class:`Terminated`, a KeyboardInterrupt, so the pool is shut down
as for Ctrl-C and the command says how to resume, with the signal's own exit status.
"""

from __future__ import annotations

import contextlib
import signal
import threading


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP during a sweep or a wear ensemble: handled as Ctrl-C is (queued cells or jobs
    cancelled, workers ended, what is finished kept), then reported with the signal's own exit status."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _raise_terminated(signum, frame):
    raise Terminated(signum)


@contextlib.contextmanager
def terminated_as_interrupt():
    """While the block runs, SIGTERM and SIGHUP raise :class:`Terminated` (a KeyboardInterrupt) in the main
    thread, so the pool is shut down as for Ctrl-C instead of the process dying without a word."""
    handled = (signal.SIGTERM, signal.SIGHUP)
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _raise_terminated) for sig in handled}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
