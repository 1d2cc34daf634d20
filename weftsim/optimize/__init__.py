"""Design optimisation (``weftsim optimize``; ``weftsim.optimize(...)``): the linkage, pin and bushing that a worn
joint hurts least, under the constraints a loom must keep.

- :mod:`.problem`: design keys with their bounds (``KEY=LOW:HIGH``, or a choice ``KEY=A,B``), designs;
- :mod:`.objectives`: the objectives (worn-joint peaks, sensitivity to clearance, pin pressure, ideal ones) and
  the run a worker makes for them;
- :mod:`.constraints`: the kinematic constraints (stroke, dead centre, transmission angle, assembly, bushing);
- :mod:`.evaluate`: constraints judged here, runs on the sweep's pool (local processes or Dask);
- :mod:`.driver`: scipy's differential evolution, the Pareto front of two objectives;
- :mod:`.store`: the directory's problem and evaluation log (resume by replay);
- :mod:`.report`, :mod:`.runner`: the report files, and planning and running it all.

See docs/optimize.md.
"""

from __future__ import annotations

import sys
import types
from pathlib import Path
from typing import Any

from weftsim.errors import OptimizeError
from weftsim.optimize.runner import OptimizeReport, format_report, plan_problem, run_problem

__all__ = ["OptimizeError", "OptimizeReport", "format_report", "optimize", "plan_problem", "run_problem"]


def optimize(scene: str | Path, vary: list[str], objectives: list[str], outdir: str | Path, *,
             constraints: list[str] | tuple = (), fixed: list[str] | tuple = (), engine: str = "reference",
             at_clearance_mm: float | None = None, allow_cwd_engine: bool = False, **options: Any) -> OptimizeReport:
    """Optimise ``scene`` over the design keys ``vary`` (``KEY=LOW:HIGH`` texts) for ``objectives`` (one, or two
    for a Pareto front) under ``constraints`` (``NAME=LOW:HIGH`` texts, or ``bushing``) into ``outdir``.

    ``fixed``: ``KEY=VALUE`` overrides of the base scene; ``at_clearance_mm``: the worn joint's clearance at E.
    ``options``: ``max_evaluations``, ``seed``, ``population``, ``front_points``, ``jobs``, ``scheduler``,
    ``compare``, ``progress`` of :func:`weftsim.optimize.runner.run_problem`.  Returns the
    :class:`OptimizeReport` (``optimum.json``'s content as ``data``).
    """
    problem = plan_problem(scene, vary, objectives, constraints, fixed, engine, at_clearance_mm, allow_cwd_engine)
    return run_problem(problem, outdir, **options)


class _CallableModule(types.ModuleType):
    """``weftsim.optimize(...)`` is :func:`optimize`, whether ``weftsim.optimize`` names the function or this
    subpackage (once ``import weftsim.optimize`` has run)."""

    def __call__(self, *args, **kwargs):
        return optimize(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
