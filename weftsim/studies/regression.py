"""Regression table of peaks (tests/regression/peaks.json): cases, quantities, tolerances.

Only reproducible quantities are stored (docs/physics.md section 6):

- ideal joint: min and max of the driving torque and the rapier acceleration;
- clearance, first revolution: min and max of the driving torque and the rapier
  acceleration, max of the contact force (the start-up impact from the centred journal
  dominates them), and the crank angle of the first contact;
- clearance, statistics over revolutions 2..N: RMS of the acceleration, the torque and
  the contact force, mean contact force.

Tolerances are measured, not guessed: each case is rerun with perturbations of the
solver that change nothing but round-off and the error control (reference: rtol x (1 +
1e-7), rtol / 10; Exudyn's rigid-body model: the python callback route instead of the numba
one, Newton tolerance / 10; its kinematic tree, the model its automatic selection takes for a
clearance: the python callback route instead of numba, rtol x (1 + 1e-7), rtol / 10;
statistics cases a few more, :data:`STATISTICS_PERTURBATIONS`) and
each quantity's tolerance is ``SAFETY[kind]`` times its largest relative shift, but at
least ``FLOOR[kind]``.  The table records the shifts, the
perturbations and the rule next to each value.  ``scripts/regenerate_regression.py``
rebuilds the table; ``tests/test_regression.py`` recomputes every case and compares.
"""

from __future__ import annotations

import math
import platform
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from weftsim.post.results import RunResult

# kind -> floor on the relative tolerance, and the factor on the largest measured shift.
FLOOR = {
    "ideal": 1e-6,  # closed form / smooth run: round-off is ~1e-12; 1e-6 leaves room for other BLAS and libm
    "first_revolution": 1e-5,  # the located onset and event steps move peaks at the 1e-6 level under round-off
    "statistics": 1e-3,
}
SAFETY = {"ideal": 10.0, "first_revolution": 10.0, "statistics": 3.0}
FIRST_CONTACT_ATOL_DEG = 1e-6  # the onset is located to ~1e-12 deg (events); this leaves round-off room
SLOW_CASE_S = 15.0  # cases measured slower than this (on the generating machine) are marked slow

PEAK_QUANTITIES = (("driving_torque_Nm", "min"), ("driving_torque_Nm", "max"),
                   ("rapier_acceleration_m_s2", "min"), ("rapier_acceleration_m_s2", "max"))
STAT_QUANTITIES = (("rapier_acceleration_m_s2", "rms"), ("driving_torque_Nm", "rms"),
                   ("contact_force_N", "rms"), ("contact_force_N", "mean"))

PERTURBATIONS = {
    "reference": (("rtol x (1 + 1e-7)", {"solver.reference.rtol": "scale:1.0000001"}),
                  ("rtol / 10", {"solver.reference.rtol": "scale:0.1"})),
    "exudyn": (("python callback route", {"solver.exudyn.callback": "python"}),
               ("Newton tolerance / 10", {"solver.exudyn.newton_relative_tolerance": "scale:0.1"})),
    "exudyn kinematic_tree": (("python callback route", {"solver.exudyn.callback": "python"}),
                              ("rtol x (1 + 1e-7)", {"solver.exudyn.relative_tolerance": "scale:1.0000001"}),
                              ("rtol / 10", {"solver.exudyn.relative_tolerance": "scale:0.1"})),
}
# Statistics scatter like samples of a chaotic impact sequence: more perturbations for a fairer largest shift.
STATISTICS_PERTURBATIONS = {
    "reference": (("rtol x (1 - 1e-7)", {"solver.reference.rtol": "scale:0.9999999"}),
                  ("atol x 10", {"solver.reference.atol": "scale:10"})),
    "exudyn": (("Newton tolerance / 2", {"solver.exudyn.newton_relative_tolerance": "scale:0.5"}),),
    "exudyn kinematic_tree": (("rtol x (1 - 1e-7)", {"solver.exudyn.relative_tolerance": "scale:0.9999999"}),),
}


@dataclass(frozen=True)
class Case:
    """One regression case: a scene file, overrides in file units, an engine and the kind of quantities."""

    name: str
    scene: str  # path relative to the repository root
    engine: str
    kind: str  # "ideal", "first_revolution" or "statistics"
    overrides: dict = field(default_factory=dict)


CASES: tuple[Case, ...] = (
    Case("ideal-400rpm-reference", "models/ideal.toml", "reference", "ideal", {"drive.revolutions": 1}),
    Case("ideal-400rpm-exudyn", "models/ideal.toml", "exudyn", "ideal", {"drive.revolutions": 1}),
    Case("c0.25mm-400rpm-reference", "models/reference.toml", "reference", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.25mm-400rpm-exudyn", "models/reference.toml", "exudyn", "first_revolution", {"drive.revolutions": 1}),
    Case("c0.50mm-400rpm-reference", "models/paper/clearance_0p50mm_400rpm.toml", "reference", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.50mm-400rpm-exudyn", "models/paper/clearance_0p50mm_400rpm.toml", "exudyn", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.25mm-800rpm-reference", "models/paper/speed_800rpm_c0p25mm.toml", "reference", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.25mm-800rpm-exudyn", "models/paper/speed_800rpm_c0p25mm.toml", "exudyn", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.01mm-400rpm-reference", "models/paper/clearance_0p01mm_400rpm.toml", "reference", "first_revolution",
         {"drive.revolutions": 1}),
    Case("c0.25mm-400rpm-reference-10rev", "models/reference.toml", "reference", "statistics",
         {"drive.revolutions": 10}),
    Case("c0.25mm-400rpm-exudyn-10rev", "models/reference.toml", "exudyn", "statistics",
         {"drive.revolutions": 10}),
)


def perturbation_key(case: Case) -> str:
    """The engine, or for Exudyn's kinematic tree (what its selection takes for the case) "exudyn kinematic_tree"."""
    if case.engine != "exudyn":
        return case.engine
    from pathlib import Path

    from weftsim.exudyn_engine.selection import select_model
    from weftsim.input.scene import load_scene

    scene = load_scene(Path(__file__).resolve().parents[2] / case.scene, case.overrides)
    return "exudyn kinematic_tree" if select_model(scene)[0] == "kinematic_tree" else "exudyn"


def perturbations(case: Case) -> tuple:
    """(label, overrides) of the perturbed reruns that set the case's tolerances."""
    key = perturbation_key(case)
    extra = STATISTICS_PERTURBATIONS[key] if case.kind == "statistics" else ()
    return PERTURBATIONS[key] + extra


def case_from_entry(entry: dict) -> Case:
    return Case(entry["case"], entry["scene"], entry["engine"], entry["kind"], dict(entry["overrides"]))


def _resolve(overrides: dict, base_scene) -> dict:
    """Turn ``"scale:f"`` override values into the base scene's value times f (file units)."""
    from weftsim.input.scene import to_file_keys

    keys = to_file_keys(base_scene)
    out = {}
    for key, value in overrides.items():
        if isinstance(value, str) and value.startswith("scale:"):
            value = keys[key] * float(value.split(":", 1)[1])
        out[key] = value
    return out


def run_case(case: Case, root: Path, extra: dict | None = None) -> RunResult:
    """Load and solve a case (``root`` = repository root); a failed run raises RuntimeError."""
    from weftsim.input.scene import load_scene
    from weftsim.studies.common import solve

    path = root / case.scene
    base = load_scene(path, case.overrides)
    scene = load_scene(path, {**case.overrides, **_resolve(extra or {}, base)})
    return solve(scene, case.engine, label=f"{case.engine} {case.name}", progress=False)


def quantities(case: Case, result: RunResult) -> dict[str, float]:
    """The stored quantities of a case, named ``<channel>.<statistic>`` (plus the first contact angle)."""
    from weftsim.post.analysis import peaks, statistics

    first = peaks(result, 0)
    out: dict[str, float] = {}
    if case.kind in ("ideal", "first_revolution"):
        for channel, stat in PEAK_QUANTITIES:
            out[f"{channel}.{stat}"] = first[channel][stat]
    if case.kind == "first_revolution":
        out["contact_force_N.max"] = first["contact_force_N"]["max"]
        if result.first_contact_angle_deg is None:
            raise ValueError(f"case {case.name} has no contact in its first revolution (its first contact angle "
                             "is a stored quantity)")
        out["first_contact_crank_angle_deg"] = result.first_contact_angle_deg
    if case.kind == "statistics":
        stats = statistics(result)
        if stats is None:
            raise ValueError(f"case {case.name} needs at least 2 revolutions for statistics")
        for channel, stat in STAT_QUANTITIES:
            out[f"{channel}.{stat}"] = stats[channel][stat]
    return {k: float(v) for k, v in out.items()}


def relative_shift(value: float, base: float) -> float:
    return abs(value - base) / abs(base) if base != 0 else abs(value)


def tolerance_entry(kind: str, name: str, value: float, shifts: dict[str, float]) -> dict:
    """{value, rtol or atol, shifts, reason} of one quantity from its measured shifts."""
    if name == "first_contact_crank_angle_deg":
        largest = max(shifts.values(), default=0.0)
        atol = max(FIRST_CONTACT_ATOL_DEG, 10.0 * largest)
        return {"value": value, "atol": atol, "shifts_deg": shifts,
                "reason": f"absolute, deg: the onset is located within the step by event location; "
                          f"largest measured shift {largest:.2g} deg, tolerance max({FIRST_CONTACT_ATOL_DEG:g}, "
                          f"10 x shift)"}
    largest = max(shifts.values(), default=0.0)
    rtol = max(FLOOR[kind], SAFETY[kind] * largest)
    what = {"ideal": "ideal-joint peak (smooth, no impacts)",
            "first_revolution": "first-revolution peak (start-up impact; moves with the located onset)",
            "statistics": "statistic over revolutions 2..N (impact sequence chaotic, averages converge)"}[kind]
    return {"value": value, "rtol": float(f"{rtol:.2g}"), "relative_shifts": shifts,
            "reason": f"{what}: largest relative shift under the perturbations {largest:.2g}; tolerance "
                      f"max({FLOOR[kind]:g}, {SAFETY[kind]:g} x shift)"}


def build_entry(case: Case, root: Path, log: Callable[[str], None] = print) -> dict:
    """Run a case and its perturbations; the table entry with values, tolerances and reasons."""
    start = time.perf_counter()
    result = run_case(case, root)
    wall = time.perf_counter() - start
    base = quantities(case, result)
    log(f"  {case.name}: {wall:.1f} s")
    shifts: dict[str, dict[str, float]] = {name: {} for name in base}
    for label, extra in perturbations(case):
        t0 = time.perf_counter()
        perturbed = quantities(case, run_case(case, root, extra))
        log(f"    perturbation {label}: {time.perf_counter() - t0:.1f} s")
        for name, value in perturbed.items():
            if name == "first_contact_crank_angle_deg":
                shifts[name][label] = abs(value - base[name])
            else:
                shifts[name][label] = relative_shift(value, base[name])
    return {
        "case": case.name,
        "scene": case.scene,
        "engine": case.engine,
        "kind": case.kind,
        "overrides": case.overrides,
        "wall_time_s": round(wall, 2),
        "slow": wall > SLOW_CASE_S,
        "quantities": {name: tolerance_entry(case.kind, name, value, shifts[name]) for name, value in base.items()},
    }


def check_entry(entry: dict, computed: dict[str, float]) -> list[str]:
    """Messages for every stored quantity outside its tolerance (empty when all pass)."""
    problems = []
    where = f"scene {entry['scene']} ({entry['engine']} engine, case {entry['case']})"
    for name, stored in entry["quantities"].items():
        value = computed.get(name)
        if value is None or not math.isfinite(value):
            problems.append(f"{where}, {name}: not computed (got {value!r}), stored {stored['value']:.10g}")
            continue
        if "atol" in stored:
            difference = abs(value - stored["value"])
            if difference > stored["atol"]:
                problems.append(f"{where}, {name}: {value:.10g} vs stored {stored['value']:.10g}, difference "
                                f"{difference:.3g} > atol {stored['atol']:.3g} ({stored['reason']})")
        else:
            difference = relative_shift(value, stored["value"])
            if difference > stored["rtol"]:
                problems.append(f"{where}, {name}: {value:.10g} vs stored {stored['value']:.10g}, relative "
                                f"difference {difference:.3g} > rtol {stored['rtol']:.3g} ({stored['reason']})")
    return problems


def environment() -> dict:
    """Versions and platform of the machine that generates the table (exudyn's from its metadata)."""
    from importlib.metadata import PackageNotFoundError, version

    out: dict[str, str | None] = {"python": platform.python_version(), "machine": platform.machine(),
                                  "system": platform.system()}
    for package in ("numpy", "scipy", "exudyn", "numba"):
        try:
            out[package] = version(package)
        except PackageNotFoundError:
            out[package] = None
    return out


def rules() -> dict:
    """How the tolerances are set (stored in the table's header)."""
    return {
        "perturbations": {engine: [label for label, _ in items] for engine, items in PERTURBATIONS.items()},
        "statistics_perturbations": {engine: [label for label, _ in items]
                                     for engine, items in STATISTICS_PERTURBATIONS.items()},
        "floor": FLOOR,
        "safety_factor": SAFETY,
        "first_contact_atol_deg": FIRST_CONTACT_ATOL_DEG,
        "slow_case_s": SLOW_CASE_S,
    }
