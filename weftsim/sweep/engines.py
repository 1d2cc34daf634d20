"""Which ``solve`` a sweep runs: a named engine or a plug-in ``module:function``.

A plug-in engine is **code that runs**: naming ``--engine mypackage.mymodel:solve`` imports
``mypackage.mymodel`` (executing it, as any plug-in or ``python -c "import ..."`` does) in the
sweep process and in every worker, and calls its ``solve(scene, progress=None)`` for each
cell.  Only name modules you trust.  A module found in the current working directory is
refused unless ``--allow-cwd-engine`` is given: the directory a command happens to run in
(a downloaded data set, a colleague's results) should not be able to inject code under a
plausible module name, the risk Python's own ``-P`` / ``PYTHONSAFEPATH`` option addresses.
"""

from __future__ import annotations

import functools
import importlib.util
import os
from pathlib import Path
from typing import Callable

from weftsim import engines
from weftsim.errors import EngineError
from weftsim.sweep.grid import SweepError

# The named engines (weftsim.engines, the one registry); anything else is a plug-in ``module:attribute``.
ENGINES = engines.BUILT_IN
CWD_FLAG = "--allow-cwd-engine"


def split_engine(engine: str) -> tuple[str, str]:
    """(module, attribute) of an engine name or ``module:attribute`` (:func:`weftsim.engines.split`)."""
    try:
        return engines.split(ENGINES.get(engine, engine))
    except EngineError:
        raise SweepError(f"--engine must be one of {', '.join(engines.names())} or module:function "
                         f"(e.g. mypackage.model:solve), got {engine!r}") from None


def _location(module: str) -> Path | None:
    """Directory the top-level package or module of ``module`` would be imported from (nothing is run)."""
    top = module.partition(".")[0]
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return None
    if spec is None:
        return None
    if spec.submodule_search_locations:
        return Path(list(spec.submodule_search_locations)[0]).resolve().parent
    return Path(spec.origin).resolve().parent if spec.origin and spec.has_location else None


def check_engine(engine: str, allow_cwd: bool = False) -> engines.Engine:
    """The engine of ``engine`` in the sweep process (:func:`weftsim.engines.get`), or one SweepError line.

    Named and registered engines are always allowed; a plug-in module from the current working directory
    only with ``allow_cwd``.  Any failure of the import (missing module, syntax error, an exception the
    module raises) is reported with its kind and message.
    """
    if engine == engines.AUTO or engine in engines.names():
        return engines.get(engine)
    module, _ = split_engine(engine)
    if not allow_cwd and _location(module) == Path(os.getcwd()).resolve():
        raise SweepError(f"--engine {engine}: module {module.partition('.')[0]!r} would be imported from the "
                         f"current directory {os.getcwd()}; a plug-in engine is code that runs, so this is "
                         f"refused unless you pass {CWD_FLAG} (or install the module)")
    try:
        return engines.get(engine)
    except EngineError as exc:
        raise SweepError(f"--engine {str(exc).removeprefix('engine ')}") from None


def _quiet(text: str) -> None:
    """A sweep cell's before-run warnings: not printed per cell (``result.plausibility["checks"]`` keeps them)."""


@functools.lru_cache(maxsize=None)
def engine_solve(engine: str) -> Callable:
    """``solve(scene, progress=None)`` of a cell in a worker: :func:`weftsim.api.simulate` on ``engine`` (the
    engine imported once per process: later cells reuse the module, its compiled code and numba cache)."""
    from weftsim.engines import simulate

    engines.get(engine)  # import now (the worker's initializer), fail here rather than in the first cell

    def solve(scene, progress=None):
        return simulate(scene, engine, progress=progress, on_warning=_quiet)

    return solve
