"""Design sweeps (``weftsim sweep``): a grid of scene variants run in parallel, resumably, tabulated.

- :mod:`.grid`: the ``--vary`` / ``--set`` grammar and the cells of a grid;
- :mod:`.plan`: the validated plan of a sweep (:func:`plan_sweep`);
- :mod:`weftsim.sweep.engines`: named and plug-in engines (a plug-in is code that runs);
- :mod:`.cell`: one cell solved in a worker from data, and its record on disk;
- :mod:`.pool`, :mod:`.worker`: the local process pool (workers die with the sweep) or a Dask cluster;
- :mod:`.lock`: one sweep at a time in a directory;
- :mod:`.store`: the sweep's directory (``sweep.json``, ``sweep.csv``);
- :mod:`.runner`: running a sweep (:func:`run_sweep`);
- :mod:`.plots`: the sweep figure.

See docs/sweeps.md.
"""

from __future__ import annotations

import sys
import types
from collections.abc import Callable
from pathlib import Path

from weftsim.sweep.grid import SweepError
from weftsim.sweep.plan import LARGE_GRID_CELLS, SweepPlan, plan_sweep
from weftsim.sweep.runner import SweepReport, format_report, run_sweep

__all__ = ["LARGE_GRID_CELLS", "SweepError", "SweepPlan", "SweepReport", "format_report", "plan_sweep", "run_sweep",
           "sweep"]


def sweep(scene: str | Path, vary: list[str], outdir: str | Path, *, fixed: list[str] | tuple = (),
          engine: str = "reference", jobs: int | None = None, scheduler: str | None = None,
          cell_figures: bool = False, allow_large: bool = False, allow_cwd_engine: bool = False,
          announce: Callable[[str], None] | None = None, progress: bool = True) -> SweepReport:
    """A parameter sweep (``weftsim sweep``; ``weftsim.sweep(...)``): every cell of the grid ``vary``
    (``KEY=V1,V2,...`` or ``KEY=LOW:HIGH:N`` texts) of ``scene`` with ``fixed`` (``KEY=VALUE`` texts) on
    ``engine``, resumable, into ``outdir``.

    Each cell runs through :func:`weftsim.simulate` (before-run checks, the engine, the vetting).  Returns the
    :class:`SweepReport` (counts, the table ``sweep.csv``, the figure); :func:`weftsim.load_sweep` reads the
    grid back.  ``announce`` receives the plan's lines (validation of a large grid, its notes).
    """
    plan = plan_sweep(scene, vary, fixed, engine, allow_large=allow_large, allow_cwd_engine=allow_cwd_engine,
                      announce=announce)
    for note in plan.notes:
        if announce is not None:
            announce(f"weftsim sweep: {note}")
    return run_sweep(plan, outdir, jobs=jobs, scheduler=scheduler, cell_figures=cell_figures, progress=progress)


class _CallableModule(types.ModuleType):
    """``weftsim.sweep(...)`` is :func:`sweep`, whether ``weftsim.sweep`` names the function (``import weftsim``)
    or this subpackage (once ``import weftsim.sweep`` has run)."""

    def __call__(self, *args, **kwargs):
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

