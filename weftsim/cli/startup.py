"""A Ctrl-C while the ``weftsim`` command is still importing: one line and exit status 130, no traceback.

The command's first import (``weftsim`` and, through it, numpy, scipy and numba) takes ~0.4 s before
:func:`weftsim.cli.commands.main` runs and can catch a KeyboardInterrupt; a Ctrl-C in that time printed
Python's traceback of whatever module was loading (issue 35: an ImportError of Exudyn's compiled module, a
numba RuntimeError, or a bare KeyboardInterrupt).  :func:`guard_command_start`, the first thing
``weftsim/__init__.py`` does, installs a SIGINT handler that ends the process at once, only when this
process is the ``weftsim`` command (the console script or ``python -m weftsim`` / ``weftsim.cli``) and
SIGINT has Python's default handler (an ignored SIGINT stays ignored).  Nothing has been computed or
written yet, so there is nothing to keep.  :func:`release` (called by ``main``) gives SIGINT back to Python.
"""

from __future__ import annotations

import gc
import os
import signal
import sys

_LINE = b"weftsim: interrupted while starting\n"
EXIT_INTERRUPTED = 128 + signal.SIGINT  # 130, as a shell reports a command stopped by Ctrl-C (every command's)


def _stop(signum, frame) -> None:  # noqa: ARG001 (a signal handler's signature)
    os.write(2, _LINE)
    os._exit(EXIT_INTERRUPTED)


def is_command() -> bool:
    """Is this process the ``weftsim`` command (console script, ``python -m weftsim``, ``-m weftsim.cli``)?"""
    if sys.argv and os.path.basename(sys.argv[0]) in ("weftsim", "weftsim.exe"):
        return True
    argv = list(getattr(sys, "orig_argv", ()))
    return any(a == "-m" and b in ("weftsim", "weftsim.cli") for a, b in zip(argv, argv[1:]))


def guard_command_start() -> None:
    if is_command() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        try:
            signal.signal(signal.SIGINT, _stop)
        except ValueError:  # not the main thread: leave it
            pass


def release() -> None:
    """SIGINT raises KeyboardInterrupt again (the commands catch it from here on)."""
    if signal.getsignal(signal.SIGINT) is _stop:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def skip_final_collection() -> None:
    """At the end of the ``weftsim`` command: no garbage collection over what the run built as the process exits.

    Python's shutdown collects every object still alive (numba's typing tables and loaded kernels, matplotlib's
    artists: ~10^5 objects after a run), 0.3-0.45 s of CPU after a ``weftsim run`` of the loom had written
    everything (issue 36, "the first second"; 0.3 s after a script that compiles one numba function).
    ``gc.freeze()`` moves them to the permanent generation, which that collection skips; the memory goes back
    with the process.  Every file is closed and the standard streams are flushed by then.  Only in the command's
    own process: a caller of :func:`weftsim.cli.commands.main` in its own program keeps collecting.
    """
    if is_command():
        gc.freeze()
