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
import importlib
import importlib.util
import os
from pathlib import Path
from typing import Callable

from weftsim.sweep.grid import SweepError

# Engine names -> "module:function" of solve(scene, progress=None) -> RunResult.
ENGINES = {"reference": "weftsim.reference:solve", "exudyn": "weftsim.exudyn_engine:solve"}
CWD_FLAG = "--allow-cwd-engine"


def split_engine(engine: str) -> tuple[str, str]:
    """(module, function) of an engine name or ``module:function``."""
    module, sep, function = ENGINES.get(engine, engine).partition(":")
    if not sep or not module or not function or not all(part.isidentifier() for part in module.split(".")) \
            or not function.isidentifier():
        raise SweepError(f"--engine must be one of {', '.join(ENGINES)} or module:function "
                         f"(e.g. mypackage.model:solve), got {engine!r}")
    return module, function


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


def check_engine(engine: str, allow_cwd: bool = False) -> Callable:
    """Import and return the engine's ``solve`` in the sweep process, or one SweepError line.

    Named engines are always allowed; a plug-in module from the current working directory only
    with ``allow_cwd``.  Any failure of the import (missing module, syntax error, an exception the
    module raises) is reported with its kind and message.
    """
    module, function = split_engine(engine)
    if engine not in ENGINES and not allow_cwd and _location(module) == Path(os.getcwd()).resolve():
        raise SweepError(f"--engine {engine}: module {module.partition('.')[0]!r} would be imported from the "
                         f"current directory {os.getcwd()}; a plug-in engine is code that runs, so this is "
                         f"refused unless you pass {CWD_FLAG} (or install the module)")
    try:
        imported = importlib.import_module(module)
    except SyntaxError as exc:
        raise SweepError(f"--engine {engine}: module {module} has a syntax error "
                         f"({exc.filename}, line {exc.lineno}: {exc.msg})") from None
    except Exception as exc:  # noqa: BLE001 - importing runs arbitrary code: any failure is the plug-in's
        raise SweepError(f"--engine {engine}: cannot import {module} ({type(exc).__name__}: {exc})") from None
    solve = getattr(imported, function, None)
    if not callable(solve):
        raise SweepError(f"--engine {engine}: module {module} has no function {function!r}")
    return solve


@functools.lru_cache(maxsize=None)
def engine_solve(engine: str) -> Callable:
    """The engine's ``solve`` in a worker, imported once per process (later cells reuse the module,
    its compiled code and its loaded numba cache)."""
    module, function = split_engine(engine)
    return getattr(importlib.import_module(module), function)
