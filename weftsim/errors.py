"""The exceptions weftsim raises on purpose: one hierarchy under :class:`WeftsimError`.

Every expected failure (a bad scene, an unwritable output directory, an unknown engine, a run
that failed, a missing optional package) is one of these, and its message is the line the
command line prints after ``weftsim COMMAND: error:``.  A script catches them all with
``except weftsim.WeftsimError``; each also derives from the built-in exception a caller would
expect (``ValueError`` for bad input, ``OSError`` for files, ``ImportError`` for a missing
package), so code written against those keeps working.

``exit_status`` is the status the ``weftsim`` command ends with (the ``EXIT_*`` statuses below, which the
command line, ``compare`` and the viewer share; :mod:`weftsim.cli.exitcodes` re-exports them).
"""

from __future__ import annotations

import difflib
from typing import Any, Iterable

# Exit statuses of the ``weftsim`` command.
EXIT_OK = 0
EXIT_USAGE = 2  # bad scene, flag or output directory
EXIT_FAILED = 3  # the simulation itself failed (partial results written)
EXIT_DISAGREE = 4  # compare: engines disagree beyond the scene's tolerance
EXIT_PARTIAL = 5  # compare: what was compared agrees, but the core checks could not be compared (run too short)


class WeftsimError(Exception):
    """Base class of every error weftsim raises on purpose; the message is one line for a person."""

    exit_status: int = EXIT_USAGE


class SceneError(WeftsimError, ValueError):
    """A scene file, a bundled scene name or an override is not acceptable (names the file, key and value)."""


class EngineError(WeftsimError, ValueError):
    """An engine name that is not one of :data:`weftsim.api.ENGINE_NAMES`."""


class ArgumentError(WeftsimError, TypeError, ValueError):
    """A function of the Python interface got an argument of the wrong kind or value (names it and what it
    takes); a TypeError and a ValueError both, for code written against either."""


class OutputError(WeftsimError, OSError):
    """The output directory or a file in it cannot be written, or a saved result cannot be read."""


class WriteFailed(OutputError):
    """The results were computed but some files could not be written; the message says where
    each one is (written, rescued, or lost with the reason)."""

    exit_status = EXIT_FAILED


class RunFailed(WeftsimError, RuntimeError):
    """A simulation ended with ``status = "failed"``; :attr:`result` keeps what it computed (a
    :class:`weftsim.post.results.RunResult`, or None).

    The attribute is typed loosely on purpose: this module is the bottom of weftsim's imports (every
    module raises these errors, :mod:`weftsim.post.results` among them), so it names no module above it.
    """

    exit_status = EXIT_FAILED

    def __init__(self, message: str, result: Any = None) -> None:
        super().__init__(message)
        self.result = result


class SweepError(WeftsimError, ValueError):
    """A sweep cannot be set up: bad --vary text, unknown key, invalid cell, incompatible directory."""


class OptimizeError(WeftsimError, ValueError):
    """An optimisation cannot be set up: unknown design key, bad bounds, unknown objective or constraint, a
    directory holding another problem."""


class StudyError(WeftsimError, ValueError):
    """A study cannot run: unknown name, missing scene file or bad setting."""


class SimulationFailed(StudyError):
    """A simulation of a study ended with ``status = "failed"``."""

    exit_status = EXIT_FAILED


class WearError(WeftsimError, ValueError):
    """A wear prediction cannot be made (bad request or a failed simulation): one line."""


class MissingExtra(WeftsimError, ImportError):
    """An optional package is not installed; the message names the extra that installs it."""


def closest(word: str, choices: Iterable[str], cutoff: float = 0.6) -> str | None:
    """The choice closest in spelling to a mistyped ``word`` (for "did you mean ...?"), or None.

    The one suggestion helper of weftsim: the command line's parser and the Python interface both use it,
    so ``weftsim run --engine exudin`` and ``weftsim.simulate(scene, "exudin")`` suggest the same name.
    """
    near = difflib.get_close_matches(word, list(choices), n=1, cutoff=cutoff)
    return near[0] if near else None


def require(module: str, extra: str, purpose: str) -> Any:
    """Import and return the optional ``module``, or raise :class:`MissingExtra` naming ``extra``.

    Parameters
    ----------
    module : str
        The importable name, e.g. ``"pandas"``.
    extra : str
        The optional extra of weftsim that installs it, e.g. ``"data"``.
    purpose : str
        What needs it, for the message (``"RunResult.to_pandas"``).
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtra(f"{purpose} needs {module}, which is not installed; install it with "
                           f"{install_command(extra)} (or pip install {module})") from None


def install_command(extra: str, root: Any = None) -> str:
    """How to install weftsim's optional ``extra`` where this weftsim comes from: ``pip install 'weftsim[data]'``
    for an installed package, ``pip install -e '.[data]'`` in the directory of a source checkout (there is no
    package named weftsim to fetch for it).  ``root``: the directory above the package (default: this one's)."""
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent if root is None else Path(root)
    if (root / "pyproject.toml").is_file() and (root / "weftsim" / "errors.py").is_file():
        return f"pip install -e '.[{extra}]' in {root} (this source checkout)"
    return f"pip install 'weftsim[{extra}]'"


class PlausibilityWarning(UserWarning):
    """A scene value outside what a real loom is built for (weftsim.checks.design_checks); the run goes on."""
