"""Work-precision benchmark: every engine over its settings against a converged solution.

One command (``weftsim bench``, or ``python -m weftsim.bench``) runs, for an easy and two
hard scenes, each engine setting of :func:`settings` and measures

- wall and CPU time of ``solve`` (median of ``repeats`` runs; runs too long to repeat whole
  are timed on ``timing_revolutions`` instead, and the table says so);
- the error of the reproducible quantities (docs/physics.md section 6) against the converged
  solution of the same scene (:func:`converged_solution`): the first revolution's maxima of
  driving torque, rapier acceleration and contact force, and the RMS and mean over
  revolutions 2..N (N = 10 by default; means are compared relative to the RMS, since the
  mean rapier acceleration over whole revolutions is ~0);
- steps, rejected steps, the first contact angle; failed runs with their reason.

The report (tables, figures, machine, versions) is written by :mod:`weftsim.bench.report`.
Speed is measured here only; no test asserts wall-clock limits.
"""

from __future__ import annotations

import math
import statistics as _stats
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

from weftsim.post.analysis import complete_revolutions, peaks, statistics

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult

QUANTITY_CHANNELS = ("driving_torque_Nm", "rapier_acceleration_m_s2", "contact_force_N")
CASES = {
    "c0.25mm-400rpm": {"joint_e.clearance_mm": 0.25, "drive.speed_rpm": 400.0},
    "c0.01mm-800rpm": {"joint_e.clearance_mm": 0.01, "drive.speed_rpm": 800.0},
    "c0.50mm-800rpm": {"joint_e.clearance_mm": 0.50, "drive.speed_rpm": 800.0},
    # Issue 23: friction makes the contact stiff (the modified Coulomb ramp, 0.1 mm/s wide).
    "c0.50mm-400rpm-mu0.15": {"joint_e.clearance_mm": 0.50, "drive.speed_rpm": 400.0,
                              "joint_e.friction_coefficient": 0.15},
}
# Cases whose converged ensemble cannot be explicit (DOP853 steps at ~1e-9 s where the journal sticks: hours at
# rtol 1e-12): the linearly implicit RODAS4 at tight tolerances instead (its first-revolution peaks agree with
# explicit DOP853 at rtol 1e-8 to 4e-5, tests/test_rosenbrock.py).
# Issue 36: the loom (models/loom.toml, 600 rpm) with friction at E, new and worn; timed by `bench --targets`
# against the same scene dry, not part of the full benchmark's cases.
LOOM_CASES = {
    "loom-c0.02mm-mu0.15": {"scene": "loom", "joint_e.clearance_mm": 0.02, "joint_e.friction_coefficient": 0.15},
    "loom-c0.10mm-mu0.15": {"scene": "loom", "joint_e.clearance_mm": 0.10, "joint_e.friction_coefficient": 0.15},
}
# Issue 36: the oiled loom (models/loom_oiled.toml: c = 0.02 mm, ISO VG 220, the journal borne by the film), Exudyn
# against the reference engine; timed by `bench --targets`.
OILED_CASES = {"loom-oiled": {"scene": "loom_oiled"}}
STIFF_CASES = ("c0.50mm-400rpm-mu0.15",) + tuple(LOOM_CASES) + tuple(OILED_CASES)
CONVERGED_STIFF = (("numba_RODAS4", 1e-10), ("numba_RODAS4", 1e-9), ("numba_DOP853_RODAS4", 1e-9))
# The loom with friction under the cylindrical law: RODAS4 alone at these tolerances crawls through the stick-slip
# chatter (c = 0.02 mm, 2 rev: 4.35 million steps at rtol 1e-8, and at 1e-9 / 1e-10 it records more steps than half
# the free memory before 90 / 529 deg, 3 December 2026), so the ensemble is the default hybrid (DOP853, RODAS4 near
# the friction ramp) at three tight tolerances (c = 0.02 mm: 470 k steps at 1e-10 in 5 s; c = 0.1 mm: 2.47 million
# steps in 34 s).
CONVERGED_LOOM = (("numba_DOP853_RODAS4", 1e-10), ("numba_DOP853_RODAS4", 3e-10), ("numba_DOP853_RODAS4", 1e-9))
# The converged solution: compiled DOP853 at the tightest tolerances; the spread of the ensemble is
# the floor below which errors are not meaningful (docs/physics.md section 6: statistics reproduce to 1-2 %).
CONVERGED = (("numba_DOP853", 1e-12), ("numba_DOP853", 1e-11), ("numba_DOP853", 1e-10), ("numba_RK45", 1e-10))
TARGETS = {"peak": 0.01, "stats": 0.02}  # issue 6: < 1 % first-revolution peaks, < 2 % statistics


@dataclass(frozen=True)
class Setting:
    """One engine configuration: scene-file overrides (file units) and its plot series."""

    engine: str  # "reference" or "exudyn"
    family: str  # series in the figures, e.g. "reference numba_DOP853"
    label: str  # the varied value, e.g. "rtol 1e-06"
    overrides: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"{self.family} {self.label}"


def _ref(method: str, rtol: float) -> Setting:
    return Setting("reference", f"reference {method}", f"rtol {rtol:.0e}",
                   {"solver.reference.method": method, "solver.reference.rtol": rtol,
                    "solver.reference.atol": rtol * 1e-3})  # fmt: skip


def _tree(rtol: float, method: str = "DOPRI5", route: str = "python") -> Setting:
    return Setting("exudyn", f"exudyn tree {method} {route}", f"rtol {rtol:.0e}",
                   {"solver.exudyn.model": "kinematic_tree", "solver.exudyn.explicit_method": method,
                    "solver.exudyn.relative_tolerance": rtol, "solver.exudyn.absolute_tolerance": rtol * 1e-3,
                    "solver.exudyn.callback": route})  # fmt: skip


def _rigid(step: float, route: str = "auto") -> Setting:
    return Setting("exudyn", f"exudyn rigid_body {route}", f"h {step:.0e} s",
                   {"solver.exudyn.model": "rigid_body", "solver.exudyn.step_control": "fixed",
                    "solver.exudyn.step_size_s": step, "solver.exudyn.callback": route})  # fmt: skip


def _rigid_adaptive(local_error: float, route: str = "auto") -> Setting:
    return Setting("exudyn", f"exudyn rigid_body adaptive {route}", f"tol {local_error:.0e} m",
                   {"solver.exudyn.model": "rigid_body", "solver.exudyn.step_control": "adaptive",
                    "solver.exudyn.local_error_m": local_error, "solver.exudyn.callback": route})  # fmt: skip


def settings(case: str, quick: bool = False) -> list[Setting]:
    """The engine settings benchmarked on one case (quick: a few per engine).

    The friction case runs the reference engine's implicit paths and its default; an explicit path there costs
    ~1600x a dry run (timed on 0.1 revolution), and the Exudyn engine's explicit tree ~1400x (issue 23 part 2
    makes it implicit; its rows belong here then).
    """
    if case in STIFF_CASES:
        out = [_ref("numba_DOP853_RODAS4", r) for r in ((1e-5, 1e-6) if quick else (1e-4, 1e-5, 1e-6, 1e-7, 1e-8))]
        out += [_ref("numba_RODAS4", r) for r in ((1e-6,) if quick else (1e-5, 1e-6, 1e-7))]
        return out + [Setting("reference", "reference default", "auto", {})]
    if quick:
        out = [_ref("numba_DOP853", r) for r in (1e-5, 1e-7)] + [_ref("DOP853", 1e-7)]
        out += [_tree(r) for r in (1e-5, 1e-6)]
        if case == "c0.25mm-400rpm":
            out += [_rigid(2e-6), _rigid_adaptive(3e-10)]
        return out
    out = [_ref("numba_DOP853", r) for r in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)]
    out += [_ref("numba_RK45", r) for r in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)]
    out += [_ref("DOP853", r) for r in (1e-6, 1e-8, 1e-10)] + [_ref("LSODA", 1e-8), _ref("RK45", 1e-7)]
    out += [_tree(r) for r in (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8)]
    out += [_tree(r, "ODE23") for r in (1e-4, 1e-5)]
    out += [_tree(1e-6, route=route) for route in ("numba", "python")]
    out += [_rigid(h) for h in (4e-6, 2e-6, 1e-6)]
    out += [_rigid_adaptive(tol) for tol in (1e-8, 3e-9, 1e-9, 3e-10)]
    if case == "c0.25mm-400rpm":
        out += [_rigid(2e-6, route) for route in ("python", "numba")]
    return out


def load_case(case: str, models: str | Path, revolutions: float, overrides: dict | None = None) -> Scene:
    from weftsim.input.scene import load_scene

    keys = {**(CASES | LOOM_CASES | OILED_CASES)[case], "drive.revolutions": revolutions,
            **(overrides or {})}
    name = keys.pop("scene", "reference")
    return load_scene(Path(models) / f"{name}.toml", keys)


def _solver(engine: str):
    """``solve(scene)`` of ``engine`` through the one door (:func:`weftsim.api.simulate`: before-run checks,
    the engine's solve from the registry, the vetting), the engine imported now."""
    from weftsim.engines import simulate
    from weftsim.engines import get

    get(engine)

    def solve(scene: Scene) -> RunResult:
        return simulate(scene, engine, on_warning=lambda text: None)

    return solve


def timed_solve(scene: Scene, engine: str) -> tuple[RunResult, float, float]:
    """(result, wall s, CPU s) of one ``solve``."""
    solve = _solver(engine)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    result = solve(scene)
    return result, time.perf_counter() - wall0, time.process_time() - cpu0


def quantities(result: RunResult) -> dict | None:
    """First-revolution maxima, RMS and mean over revolutions 2..N, first contact angle."""
    n = complete_revolutions(result)
    if n < 1:
        return None
    first = peaks(result, 0)
    stats = statistics(result) if n >= 2 else None
    return {
        "revolutions": n,
        "peak": {ch: first[ch]["max"] for ch in QUANTITY_CHANNELS},
        "rms": {ch: stats[ch]["rms"] for ch in QUANTITY_CHANNELS} if stats else None,
        "mean": {ch: stats[ch]["mean"] for ch in QUANTITY_CHANNELS} if stats else None,
        "first_contact_deg": result.first_contact_angle_deg,
    }


@overload
def errors(q: dict, ref: dict) -> dict: ...
@overload
def errors(q: None, ref: dict) -> None: ...
def errors(q: dict | None, ref: dict) -> dict | None:
    """Relative errors of one run's quantities against the converged ones (means relative to the RMS)."""
    if q is None:
        return None
    out: dict[str, Any] = {"peak": {ch: _relative(q["peak"][ch], ref["peak"][ch]) for ch in QUANTITY_CHANNELS}}
    out["peak_max"] = max(out["peak"].values())
    if q["rms"] is not None and ref["rms"] is not None and q["revolutions"] >= ref["revolutions"]:
        out["rms"] = {ch: abs(q["rms"][ch] - ref["rms"][ch]) / ref["rms"][ch] for ch in QUANTITY_CHANNELS}
        out["mean"] = {ch: abs(q["mean"][ch] - ref["mean"][ch]) / ref["rms"][ch] for ch in QUANTITY_CHANNELS}
        out["stats_max"] = max(list(out["rms"].values()) + list(out["mean"].values()))
    else:
        out["stats_max"] = None
    a, b = q["first_contact_deg"], ref["first_contact_deg"]
    out["first_contact_deg"] = abs(a - b) if a is not None and b is not None else None
    return out


def _relative(value: float, converged: float) -> float:
    """abs(value - converged) / abs(converged); a channel that stays 0 in the converged run (the contact force of a
    film-borne journal) is exact at 0 and infinitely wrong elsewhere."""
    if converged == 0.0:
        return 0.0 if value == 0.0 else math.inf
    return abs(value - converged) / abs(converged)


def converged_solution(case: str, models: str | Path, revolutions: float, log: Callable[[str], None] = print,
                       overrides: dict | None = None) -> dict:
    """Quantities of the converged ensemble (:data:`CONVERGED`) and its spread (the error floor).

    Peaks come from the tightest run; RMS and mean are the median over the ensemble (they
    scatter by ~1 % from impact-sequence chaos, docs/physics.md section 6).
    """
    members = []
    stiff = case in STIFF_CASES and not (overrides or {}).get("joint_e.friction_coefficient", 1.0) == 0.0
    for method, rtol in (CONVERGED_LOOM if stiff and case in LOOM_CASES else CONVERGED_STIFF if stiff else CONVERGED):
        scene = load_case(case, models, revolutions, {**(overrides or {}), **_ref(method, rtol).overrides})
        result, wall, _ = timed_solve(scene, "reference")
        if not result.ok:
            raise RuntimeError(f"converged solution {method} rtol {rtol:g} of {case} failed: {result.message}")
        q = quantities(result)
        if q is None:
            raise RuntimeError(f"converged solution {method} rtol {rtol:g} of {case} has no complete revolution")
        members.append({"method": method, "rtol": rtol, "wall_s": wall, **q})
        log(f"  converged {case}: {method} rtol {rtol:.0e} in {wall:.2f} s")
    best = members[0]
    ref: dict[str, Any] = {"revolutions": best["revolutions"], "peak": best["peak"], "first_contact_deg": best["first_contact_deg"]}
    if best["rms"] is not None:
        ref["rms"] = {ch: _stats.median(m["rms"][ch] for m in members) for ch in QUANTITY_CHANNELS}
        ref["mean"] = {ch: _stats.median(m["mean"][ch] for m in members) for ch in QUANTITY_CHANNELS}
    else:
        ref["rms"] = ref["mean"] = None
    spread = [errors(m, ref) for m in members]
    ref["floor"] = {"peak": max(e["peak_max"] for e in spread),
                    "stats": max((e["stats_max"] or 0.0) for e in spread) if ref["rms"] else None}  # fmt: skip
    ref["members"] = members
    return ref


def measure(case: str, setting: Setting, ref: dict, models: str | Path, revolutions: float, repeats: int,
            repeat_limit: float, timing_revolutions: float) -> dict:
    """Run one setting: one full run for the errors, ``repeats`` timed runs for the time.

    The full run is repeated if it took at most ``repeat_limit`` s; otherwise the timing runs
    simulate ``timing_revolutions`` only (the loom-time ratio is then taken from them).
    """
    scene = load_case(case, models, revolutions, setting.overrides)
    result, wall, cpu = timed_solve(scene, setting.engine)
    row: dict[str, Any] = {"case": case, "engine": setting.engine, "family": setting.family, "label": setting.label,
           "setting": setting.name, "overrides": setting.overrides, "status": result.status,
           "message": result.message, "failure": result.solver_stats.get("failure"),
           "loom_time_s": scene.drive.end_time}  # fmt: skip
    stats = result.solver_stats
    row["solver_stats"] = {k: v for k, v in stats.items() if isinstance(v, (int, float, str, type(None)))}
    row["steps"], row["rejected_steps"] = stats.get("steps"), stats.get("rejected_steps")
    row["quantities"] = quantities(result)
    row["errors"] = errors(row["quantities"], ref)
    walls, cpus, timed_loom = [wall], [cpu], scene.drive.end_time
    if result.ok and repeats > 1:
        if wall <= repeat_limit:
            for _ in range(repeats - 1):
                _, w, c = timed_solve(scene, setting.engine)
                walls.append(w)
                cpus.append(c)
        else:
            timing = load_case(case, models, timing_revolutions, setting.overrides)
            timed_loom = timing.drive.end_time
            walls, cpus = [], []
            for _ in range(repeats):
                _, w, c = timed_solve(timing, setting.engine)
                walls.append(w)
                cpus.append(c)
    row["timing"] = {"runs": len(walls), "revolutions": timed_loom / scene.drive.period, "loom_time_s": timed_loom,
                     "wall_s": walls, "cpu_s": cpus, "wall_median_s": _stats.median(walls),
                     "cpu_median_s": _stats.median(cpus)}  # fmt: skip
    row["realtime_ratio"] = timed_loom / row["timing"]["wall_median_s"]
    row["realtime_ratio_cpu"] = timed_loom / row["timing"]["cpu_median_s"]
    # Time for the full run at the median rate (equal to the median itself when the full run was repeated).
    row["wall_s"] = scene.drive.end_time / row["realtime_ratio"]
    return row


def startup_costs(models: str | Path, log: Callable[[str], None] = print) -> dict:
    """First call against second call of each engine path on a tiny run (imports, numba cache, compile)."""
    out = {}
    paths = {
        "reference numba_DOP853": ("reference", _ref("numba_DOP853", 1e-6).overrides),
        "reference DOP853 (scipy)": ("reference", _ref("DOP853", 1e-6).overrides),
        "exudyn tree python": ("exudyn", _tree(1e-6).overrides),
        "exudyn tree numba": ("exudyn", _tree(1e-6, route="numba").overrides),
        "exudyn rigid_body auto": ("exudyn", _rigid(2e-6).overrides),
    }
    for name, (engine, overrides) in paths.items():
        scene = load_case("c0.25mm-400rpm", models, 0.02, overrides)
        t0 = time.perf_counter()
        _solver(engine)
        t_import = time.perf_counter() - t0
        _, first, _ = timed_solve(scene, engine)
        _, second, _ = timed_solve(scene, engine)
        out[name] = {"import_s": t_import, "first_call_s": first, "second_call_s": second,
                     "startup_s": t_import + first - second}  # fmt: skip
        log(f"  start-up {name}: import {t_import:.2f} s, first call {first:.3f} s, second {second:.3f} s")
    return out


def run_benchmark(outdir: str | Path, models: str | Path = "models", quick: bool = False,
                  cases: Sequence[str] | None = None, revolutions: float | None = None, repeats: int = 5,
                  repeat_limit: float | None = None, force: bool = False,
                  log: Callable[[str], None] | None = None) -> dict:
    """Run the whole benchmark and write its report into ``outdir``; returns the report dict."""
    from weftsim.bench.report import machine_info, write_report

    log = log or (lambda text: print(text, file=sys.stderr, flush=True))
    revolutions = revolutions or (2.0 if quick else 10.0)
    repeat_limit = repeat_limit if repeat_limit is not None else (4.0 if quick else 8.0)
    cases = list(cases or CASES)
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        raise ValueError(f"unknown cases {unknown}; choose from {list(CASES)}")
    started = time.perf_counter()
    report: dict[str, Any] = {"mode": "quick" if quick else "full", "revolutions": revolutions, "repeats": repeats,
              "repeat_limit_s": repeat_limit, "timing_revolutions": 1.0, "targets": TARGETS,
              "machine_start": machine_info(), "cases": {}}  # fmt: skip
    log("start-up costs")
    report["startup"] = startup_costs(models, log)
    for case in cases:
        log(f"case {case}")
        ref = converged_solution(case, models, revolutions, log)
        rows = []
        todo = settings(case, quick)
        for i, setting in enumerate(todo, 1):
            row = measure(case, setting, ref, models, revolutions, repeats, repeat_limit, 1.0)
            rows.append(row)
            err = row["errors"] or {}
            log(f"  [{i}/{len(todo)}] {setting.name}: {row['status']}, {row['timing']['wall_median_s']:.3f} s "
                f"median of {row['timing']['runs']} ({row['timing']['revolutions']:g} rev; x{row['realtime_ratio']:.2f} "
                f"real time), peak err {_fmt(err.get('peak_max'))}, stats err {_fmt(err.get('stats_max'))}"
                + (f" -- {row['message'][:160]}" if row["status"] != "success" else ""))  # fmt: skip
        report["cases"][case] = {"converged": ref, "runs": rows}
    report["machine_end"] = machine_info()
    report["total_time_s"] = time.perf_counter() - started
    report["files"] = write_report(report, outdir, force)
    return report


def _fmt(value) -> str:
    return "-" if value is None else f"{value:.1e}"


def main(argv: list[str] | None = None) -> int:
    import argparse

    p = argparse.ArgumentParser(prog="python -m weftsim.bench", description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="a few settings, 2 revolutions (a few minutes)")
    p.add_argument("-o", "--output", default=None, help="output directory (default: out/bench or out/bench-quick)")
    p.add_argument("--case", action="append", choices=list(CASES), help="only these cases (repeatable)")
    p.add_argument("--models", default="models", help="directory holding reference.toml")
    p.add_argument("--repeats", type=int, default=5, help="timed runs per setting (median)")
    p.add_argument("--force", action="store_true", help="write into a directory weftsim did not write")
    args = p.parse_args(argv)
    outdir = args.output or ("out/bench-quick" if args.quick else "out/bench")
    report = run_benchmark(outdir, args.models, args.quick, args.case, repeats=args.repeats, force=args.force)
    print(f"benchmark done in {report['total_time_s']:.0f} s; wrote " + ", ".join(map(str, report["files"])))
    return 0

