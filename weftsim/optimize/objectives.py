"""The objectives of ``weftsim optimize`` (all minimised) and the runs each needs.

==============================  ======  =================================================================
objective                       unit    value
==============================  ======  =================================================================
``peak_joint_force``            N       peak load at E with the worn joint (last complete revolution)
``peak_rapier_acceleration``    m/s2    peak abs(rapier acceleration) with the worn joint (same window)
``clearance_sensitivity``       1       peak joint force worn / peak joint force new - 1
``pin_pressure``                Pa      peak projected pin pressure F/(d B) at E, worn joint (design checks)
``pv``                          Pa m/s  cycle mean of p x v at E, worn joint (design checks)
``ideal_joint_force``           N       peak force at E of the ideal mechanism (no simulation)
``ideal_pin_pressure``          Pa      its peak pin pressure (the before-run design check)
``ideal_rapier_acceleration``   m/s2    peak abs(rapier acceleration) of the ideal mechanism
==============================  ======  =================================================================

The *worn* joint has the clearance ``at_clearance_mm`` (``--at-clearance-mm``; default: the design's own
``joint_e.clearance_mm``), the *new* joint the design's ``joint_e.clearance_mm``.  A worn-joint objective runs
the design once at the worn clearance on the chosen engine (``drive.revolutions`` of the scene; the peaks of
its last complete revolution, as ``weftsim sweep``'s ``*_last_peak`` columns, and the after-run design checks
from revolution 2 on); ``clearance_sensitivity`` runs it at both clearances.  The ``ideal_*`` objectives need
no run (weftsim.mechanism.pin_loads, the before-run design checks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from weftsim.errors import OptimizeError


@dataclass(frozen=True)
class Objective:
    name: str
    unit: str
    runs: tuple[str, ...]  # the runs it needs: "worn", "new" (none: the ideal mechanism)
    doc: str


OBJECTIVES = {o.name: o for o in (
    Objective("peak_joint_force", "N", ("worn",), "peak joint force at E with the worn joint"),
    Objective("peak_rapier_acceleration", "m/s2", ("worn",), "peak rapier acceleration with the worn joint"),
    Objective("clearance_sensitivity", "1", ("worn", "new"), "growth of the peak joint force from new to worn"),
    Objective("pin_pressure", "Pa", ("worn",), "peak pin pressure at E with the worn joint"),
    Objective("pv", "Pa m/s", ("worn",), "mean p x v at E with the worn joint"),
    Objective("ideal_joint_force", "N", (), "peak joint force at E of the ideal mechanism"),
    Objective("ideal_pin_pressure", "Pa", (), "peak pin pressure at E of the ideal mechanism"),
    Objective("ideal_rapier_acceleration", "m/s2", (), "peak rapier acceleration of the ideal mechanism"),
)}

# Named in the issue but not (yet) offered, with the reason: one line each.
UNAVAILABLE = {
    "hours_to_limit": "hours_to_limit is not an objective yet: each design would need a whole wear prediction "
                      "(weftsim wear, minutes to hours a design); run weftsim wear on the designs found instead",
    "exchange_error": "exchange_error is not available yet: it needs the rapier tape's exchange model, which is "
                      "still being built (docs/rapier-tape.md)",
}


def check_objectives(names: list[str], at_clearance_mm: float | None, new_clearance_mm: float) -> tuple[str, ...]:
    """The objective names, checked: known, at most two, not repeated; the clearances they need given."""
    from weftsim.errors import closest

    if not names:
        raise OptimizeError(f"give an --objective: one of {', '.join(OBJECTIVES)}")
    for name in names:
        if name in UNAVAILABLE:
            raise OptimizeError(UNAVAILABLE[name])
        if name not in OBJECTIVES:
            near = closest(name, OBJECTIVES)
            hint = f"did you mean {near}? " if near else ""
            raise OptimizeError(f"--objective: unknown objective {name!r}; {hint}choose from {', '.join(OBJECTIVES)}")
    if len(set(names)) != len(names):
        raise OptimizeError(f"--objective: {names[0]} given twice")
    if len(names) > 2:
        raise OptimizeError(f"--objective: at most two objectives (a Pareto front of two), got {len(names)}")
    if at_clearance_mm is not None and not (math.isfinite(at_clearance_mm) and at_clearance_mm > 0.0):
        raise OptimizeError(f"--at-clearance-mm must be a number > 0 (the worn joint's radial clearance at E, mm), "
                            f"got {at_clearance_mm!r}")
    if "clearance_sensitivity" in names and (at_clearance_mm is None or at_clearance_mm == new_clearance_mm):
        raise OptimizeError("clearance_sensitivity compares the new joint (joint_e.clearance_mm = "
                            f"{new_clearance_mm:g} mm) with a worn one: give --at-clearance-mm larger than that")
    if any(OBJECTIVES[n].runs for n in names) and (at_clearance_mm or new_clearance_mm) <= 0.0:
        raise OptimizeError("the worn-joint objectives need a clearance at E: give --at-clearance-mm "
                            "(joint_e.clearance_mm is 0, the ideal joint)")
    return tuple(names)


def runs_needed(names: tuple[str, ...]) -> tuple[str, ...]:
    needed = {run for name in names for run in OBJECTIVES[name].runs}
    return tuple(run for run in ("worn", "new") if run in needed)


def ideal_values(checks: list[dict]) -> dict[str, float]:
    """The ``ideal_*`` objectives from a design's before-run design checks (dicts)."""
    out: dict[str, float] = {}
    for check in checks:
        if check["stage"] != "before":
            continue
        if check["table"] == "joint_e" and check["name"] == "pin_pressure":
            out["ideal_pin_pressure"] = check["value"]
            out["ideal_joint_force"] = check["numbers"]["peak_force_n"]
        elif check["name"] == "rapier_acceleration":
            out["ideal_rapier_acceleration"] = check["value"]
    return out


def run_metrics(result: Any) -> dict[str, float | None]:
    """What the objectives read from one run (a RunResult): peaks of the last complete revolution
    (:func:`weftsim.sweep.cell.cell_metrics`) and the after-run design checks at E."""
    from weftsim.sweep.cell import cell_metrics

    metrics = cell_metrics(result)
    out: dict[str, float | None] = {"joint_force_n": metrics.get("joint_force_N_last_peak"),
                                    "rapier_acceleration_m_s2": metrics.get("rapier_acceleration_m_s2_last_peak"),
                                    "pin_pressure_pa": None, "pv_pa_m_s": None}
    for check in (result.plausibility or {}).get("checks", []):
        if check["stage"] == "after" and check["table"] == "joint_e":
            if check["name"] == "pin_pressure":
                out["pin_pressure_pa"] = check["value"]
            elif check["name"] == "pv":
                out["pv_pa_m_s"] = check["value"]
    return out


def objective_values(names: tuple[str, ...], ideal: dict[str, float], runs: dict[str, dict]) -> dict[str, float | None]:
    """Each objective's value from the ideal values and the runs' metrics (None where a number is missing)."""
    out: dict[str, float | None] = {}
    worn = runs.get("worn") or {}
    for name in names:
        if name.startswith("ideal_"):
            out[name] = ideal.get(name)
        elif name == "peak_joint_force":
            out[name] = worn.get("joint_force_n")
        elif name == "peak_rapier_acceleration":
            out[name] = worn.get("rapier_acceleration_m_s2")
        elif name == "pin_pressure":
            out[name] = worn.get("pin_pressure_pa")
        elif name == "pv":
            out[name] = worn.get("pv_pa_m_s")
        else:  # clearance_sensitivity
            new = (runs.get("new") or {}).get("joint_force_n")
            old = worn.get("joint_force_n")
            out[name] = old / new - 1.0 if old is not None and new else None
    return {k: (float(v) if v is not None and math.isfinite(v) else None) for k, v in out.items()}


def solve_design(label: str, scene_keys: dict, engine: str) -> dict[str, Any]:
    """One run of a design in a worker (the sweep's pool or Dask): the scene goes as data, the run's metrics
    come back (:func:`run_metrics`), never its files.  A failure is returned, not raised."""
    import time

    from weftsim.input.scene import scene_from_keys
    from weftsim.sweep.engines import engine_solve

    start = time.perf_counter()
    try:
        scene = scene_from_keys(scene_keys, f"design {label}")
        result = engine_solve(engine)(scene, progress=None)
        metrics = run_metrics(result) if result.ok else {}
        status, error = ("success", "") if result.ok else ("failed", result.message or "the run failed")
    except Exception as exc:  # noqa: BLE001 - a design's failure is data, not a reason to stop the optimisation
        status, error, metrics = "failed", f"{type(exc).__name__}: {exc}", {}
    return {"status": status, "error": error, "metrics": metrics, "wall_time_s": time.perf_counter() - start}
