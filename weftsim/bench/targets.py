"""The speed targets of the default paths (``weftsim bench --targets``), measured as ratios in one run.

On the easy case (``models/reference.toml``: 400 rpm, c = 0.25 mm, 10 revolutions) it measures

- ``reference.solve`` and ``exudyn_engine.solve`` with no solver key set (the automatic path);
- the Exudyn rigid-body model, forced (``solver.exudyn.model = "rigid_body"``, its other keys default);
- the slow defaults of version 0.1 in the same process, as the baselines of the ratios
  (scipy DOP853 at rtol 1e-9, the rigid-body model at a fixed step of 2e-6 s);
- ``weftsim run`` as a new process, start to exit, for 2 revolutions on each engine (after one
  warm-up process, so the numba cache exists: "after the first run on the machine");
- issue 36's first second: ``weftsim run loom --revolutions 1`` as a new process, with its figures and with
  ``--no-plot``, its CPU time (user + sys, the least of the runs: the machine may be shared) and wall time;
- the 121-cell clearance x speed map of ``scripts/paper_sweeps.py`` at 10 revolutions per cell
  on ``jobs`` processes (``map_repeats`` times; it is the longest item).

Each timed item is the median of ``repeats`` runs.  The accuracy of the in-process runs comes
from :func:`weftsim.bench.measure.measure`: first-revolution peaks against the converged
solution (target 1 %) and the 10-revolution statistics against the scatter of the converged
ensemble.  Nothing here asserts a time; the report says which targets are met.
"""

from __future__ import annotations

import resource
import statistics as _stats
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

from weftsim.bench.measure import LOOM_CASES, OILED_CASES, Setting, _ref, _rigid, converged_solution, measure

if TYPE_CHECKING:
    from collections.abc import Callable

CASE = "c0.25mm-400rpm"
# Issue 12's targets: loom time / wall time of the in-process solves, wall seconds of the rest.
TARGETS = {
    "reference default": {"ratio_at_least": 30.0},
    "exudyn default": {"ratio_at_least": 2.0},
    "exudyn rigid_body (forced)": {"ratio_at_least": 0.2},
    "weftsim run reference, new process, 2 rev": {"wall_at_most_s": 2.0},
    "weftsim run exudyn, new process, 2 rev": {"wall_at_most_s": 2.0},
    "121-cell map, 10 rev per cell": {"wall_at_most_s": 60.0},
    # issue 36, "the first second": CPU (user + sys) of the process, the least of the runs (on a shared machine,
    # the least disturbed one); the target is the wall time of an idle machine, where a one-thread run's CPU is its wall
    "weftsim run loom --revolutions 1, new process, figures": {"cpu_at_most_s": 1.0},
}
FIRST_SECOND = {"weftsim run loom --revolutions 1, new process, figures": (),
                "weftsim run loom --revolutions 1, new process, --no-plot": ("--no-plot",)}
PEAK_TARGET = 0.01  # first-revolution peaks within 1 % of the converged solution
SOLVES = {
    "reference default": Setting("reference", "reference", "default", {}),
    "exudyn default": Setting("exudyn", "exudyn", "default", {}),
    "exudyn rigid_body (forced)": Setting("exudyn", "exudyn", "rigid_body", {"solver.exudyn.model": "rigid_body"}),
    "baseline: reference scipy DOP853 rtol 1e-9 (0.1 default)": _ref("DOP853", 1e-9),
    "baseline: exudyn rigid_body h 2e-6 s (0.1 default)": _rigid(2e-6),
}
# Issue 23: friction (and, once the joint has one, an oil film) on the default path, per revolution against the
# same scene dry, over 2 revolutions (the first holds the start-up impact; the peaks are the first revolution's).
FRICTION_CASE = "c0.50mm-400rpm-mu0.15"
FRICTION_REVOLUTIONS = 2.0
FRICTION_RATIO_AT_MOST = 3.0
FRICTION_PEAK_TARGET = 0.005  # first-revolution peaks within 0.5 % of the converged (implicit) solution
DRY = {"joint_e.friction_coefficient": 0.0}
# The lubricated case: the friction case's scene (reference.toml, c = 0.5 mm, 400 rpm) without friction and with
# an oil film of 80 mPa s at joint E (the loom case's viscosity), against the
# same scene dry; target: at most 3x dry.  At c = 0.5 mm the film does not hold the journal off the wall (5
# impacts in 2 revolutions): the case times the film on top of dry contacts.  The film-borne case (the loom at
# c = 0.02 mm, 600 rpm, no contact) is measured in docs/performance.md, "Where the time goes in a lubricated run".
LUBRICATED_OVERRIDES: dict | None = {"joint_e.friction_coefficient": 0.0, "joint_e.lubrication.viscosity_mpa_s": 80.0}
MAP_VARY = ["clearance_mm=0.01,0.05,0.1,0.15,0.2,0.25,0.3,0.35,0.4,0.45,0.5", "speed_rpm=300:800:11"]


def _process_walls(commands: list[list[str]], warmup: int = 0) -> dict:
    """Wall time and CPU time (user + sys) of each command run as a new process, in turn; the first ``warmup``
    are not counted.

    Stops at the first command that fails, keeping its exit status and the end of its stderr.
    """
    walls: list[float] = []
    cpus: list[float] = []
    for i, command in enumerate(commands):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if done.returncode != 0:
            return {"status": "failed", "exit": done.returncode, "stderr": done.stderr[-400:], "wall_s": walls,
                    "command": " ".join(command[1:])}
        if i >= warmup:
            walls.append(wall)
            cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return {"status": "success", "command": " ".join(commands[-1][1:]), "wall_s": walls,
            "wall_median_s": _stats.median(walls), "cpu_s": cpus, "cpu_min_s": min(cpus)}


def cli_run(engine: str, models: str | Path, repeats: int, workdir: Path) -> dict:
    """``weftsim run`` as a new process, 2 revolutions, start to exit; ``repeats`` runs after one warm-up run."""
    command = [sys.executable, "-m", "weftsim.cli", "run", str(Path(models) / "reference.toml"), "--engine", engine,
               "--revolutions", "2", "-o", str(workdir / f"run-{engine}"), "--force"]
    return _process_walls([command] * (repeats + 1), warmup=1)


def first_second(models: str | Path, repeats: int, workdir: Path) -> dict:
    """Issue 36's first second: ``weftsim run loom --revolutions 1`` as a new process, with its figures and with
    ``--no-plot``, ``repeats`` runs each after one warm-up run (the numba cache exists)."""
    items = {}
    for name, extra in FIRST_SECOND.items():
        command = [sys.executable, "-m", "weftsim.cli", "run", str(Path(models) / "loom.toml"), "--revolutions", "1",
                   "-o", str(workdir / "first-second"), "--force", *extra]  # fmt: skip
        items[name] = _process_walls([command] * (repeats + 1), warmup=1)
    return items


def clearance_speed_map(models: str | Path, jobs: int, repeats: int, workdir: Path) -> dict:
    """The 121-cell map at 10 revolutions per cell, from scratch each time (a fresh output directory)."""
    commands = [[sys.executable, "-m", "weftsim.cli", "sweep", str(Path(models) / "reference.toml"),
                 "--vary", MAP_VARY[0], "--vary", MAP_VARY[1], "--set", "revolutions=10", "--engine", "reference",
                 "--jobs", str(jobs), "-o", str(workdir / f"map-{i}")] for i in range(repeats)]  # fmt: skip
    return {"jobs": jobs, **_process_walls(commands)}


def stiff_items(models: str | Path, repeats: int, log: Callable[[str], None] = print) -> dict:
    """The reference engine's default path on the friction case and the same scene dry (and the lubricated slot):
    both timed, each against its own converged solution, and their ratio per revolution."""
    items = {}
    refs = {"dry": converged_solution(FRICTION_CASE, models, FRICTION_REVOLUTIONS, log, DRY),
            "friction": converged_solution(FRICTION_CASE, models, FRICTION_REVOLUTIONS, log)}
    names = {"dry": "reference default, c 0.5 mm dry", "friction": "reference default, c 0.5 mm mu 0.15"}
    for key, overrides in (("dry", DRY), ("friction", {})):
        row = measure(FRICTION_CASE, Setting("reference", "reference", "default", overrides), refs[key], models,
                      FRICTION_REVOLUTIONS, repeats, 8.0, 1.0)  # fmt: skip
        items[names[key]] = row
        log(f"  {names[key]}: x{row['realtime_ratio']:.2f} real time, {row['steps']} steps, peak err "
            f"{(row['errors'] or {}).get('peak_max')}")
    dry, rough = items[names["dry"]], items[names["friction"]]
    ratio = dry["realtime_ratio"] / rough["realtime_ratio"]
    peak = (rough.get("errors") or {}).get("peak_max")
    items["friction / dry, reference default, per revolution"] = {
        "status": "success" if rough["status"] == dry["status"] == "success" else "failed", "ratio": ratio,
        "peak_error": peak, "steps": [dry["steps"], rough["steps"]],
        "met": rough["status"] == "success" and ratio <= FRICTION_RATIO_AT_MOST and peak is not None
        and peak <= FRICTION_PEAK_TARGET,
        "target_text": f"<= {FRICTION_RATIO_AT_MOST:g}x, peaks within {FRICTION_PEAK_TARGET:.1%}"}
    log(f"  friction / dry: {ratio:.2f}x, peak error {peak}")
    items["lubricated / dry, reference default, per revolution"] = (
        {"status": "not available (no lubricated joint in this version)", "met": None,
         "target_text": f"<= {FRICTION_RATIO_AT_MOST:g}x"} if LUBRICATED_OVERRIDES is None else
        _ratio_item(FRICTION_CASE, LUBRICATED_OVERRIDES, refs, dry, models, repeats))
    return items


LOOM_FRICTION_REVOLUTIONS = 1.0  # one revolution of the loom, start-up impact included (converged: RODAS4 rtol 1e-10)
LOOM_PEAK_TARGET = 1e-3  # issue 36: peaks within 0.1 % of a converged run


def _slowdown(base: dict, run: dict, ratio_at_most: float, label: str, log: Callable[[str], None]) -> dict:
    """The item of ``run``'s time against ``base``'s (wall and CPU, per loom time), judged on the ratio and on
    ``run``'s peaks (within :data:`LOOM_PEAK_TARGET` of its converged run)."""
    ratio = base["realtime_ratio"] / run["realtime_ratio"]
    cpu = base["realtime_ratio_cpu"] / run["realtime_ratio_cpu"]
    peak = (run.get("errors") or {}).get("peak_max")
    ok = run["status"] == base["status"] == "success"
    log(f"  {label}: {ratio:.2f}x wall, {cpu:.2f}x CPU, steps {base['steps']} / {run['steps']}, peak error {peak}")
    return {"status": "success" if ok else "failed", "ratio": ratio, "cpu_ratio": cpu, "peak_error": peak,
            "steps": [base["steps"], run["steps"]],
            "met": ok and ratio <= ratio_at_most and peak is not None and peak <= LOOM_PEAK_TARGET,
            "target_text": f"<= {ratio_at_most:g}x, peaks within {LOOM_PEAK_TARGET:.1%}"}


def loom_friction_items(models: str | Path, repeats: int, log: Callable[[str], None] = print) -> dict:
    """Issue 36: the loom with mu = 0.15 against the same scene dry, per revolution, at c = 0.02 and 0.1 mm, on
    both engines' default paths; the peaks of each against the reference engine's converged run of its scene."""
    items = {}
    for case in LOOM_CASES:
        refs = {"dry": converged_solution(case, models, LOOM_FRICTION_REVOLUTIONS, log, DRY),
                "friction": converged_solution(case, models, LOOM_FRICTION_REVOLUTIONS, log)}
        for engine in ("reference", "exudyn"):
            rows = {}
            for key, overrides in (("dry", DRY), ("friction", {})):
                rows[key] = measure(case, Setting(engine, engine, "default", overrides), refs[key], models,
                                    LOOM_FRICTION_REVOLUTIONS, repeats, 8.0, 1.0)  # fmt: skip
                items[f"{engine} default, {case}, {key}"] = rows[key]
            items[f"friction / dry, {engine} default, {case}"] = _slowdown(
                rows["dry"], rows["friction"], FRICTION_RATIO_AT_MOST, f"friction / dry, {engine}, {case}", log)
    return items


OILED_RATIO_AT_MOST = 3.0  # issue 36: the oiled loom on Exudyn at most 3x the reference engine's time


def loom_oiled_items(models: str | Path, repeats: int, log: Callable[[str], None] = print) -> dict:
    """Issue 36: the oiled loom (one revolution) on both engines' default paths, Exudyn's time against the
    reference engine's; the peaks of each against the reference engine's converged run (RODAS4 rtol 1e-10)."""
    items = {}
    for case in OILED_CASES:
        ref = converged_solution(case, models, LOOM_FRICTION_REVOLUTIONS, log)
        rows = {engine: measure(case, Setting(engine, engine, "default", {}), ref, models, LOOM_FRICTION_REVOLUTIONS,
                                repeats, 8.0, 1.0) for engine in ("reference", "exudyn")}  # fmt: skip
        for engine, row in rows.items():
            items[f"{engine} default, {case}"] = row
        items[f"exudyn / reference, default, {case}"] = _slowdown(
            rows["reference"], rows["exudyn"], OILED_RATIO_AT_MOST, f"exudyn / reference, {case}", log)
    return items


def _ratio_item(case: str, overrides: dict, refs: dict, dry: dict, models, repeats: int) -> dict:
    """The lubricated run's time against the dry one's; its errors are against the dry solution (a film changes
    the peaks), so only the ratio is judged here; its accuracy needs a converged lubricated ensemble."""
    row = measure(case, Setting("reference", "reference", "default", overrides), refs["dry"], models,
                  FRICTION_REVOLUTIONS, repeats, 8.0, 1.0)  # fmt: skip
    ratio = dry["realtime_ratio"] / row["realtime_ratio"]
    return {"status": row["status"], "ratio": ratio, "steps": [dry["steps"], row["steps"]],
            "met": row["status"] == "success" and ratio <= FRICTION_RATIO_AT_MOST,
            "target_text": f"<= {FRICTION_RATIO_AT_MOST:g}x", "run": row}


def _met(name: str, item: dict) -> bool | None:
    if "met" in item and name not in TARGETS:  # the stiff items judge themselves (stiff_items)
        return item["met"]
    target = TARGETS.get(name)
    if target is None or item.get("status") != "success":
        return None if target is None else False
    if "ratio_at_least" in target:
        peak = (item.get("errors") or {}).get("peak_max")
        return item["realtime_ratio"] >= target["ratio_at_least"] and peak is not None and peak <= PEAK_TARGET
    if "cpu_at_most_s" in target:
        return item["cpu_min_s"] <= target["cpu_at_most_s"]
    return item["wall_median_s"] <= target["wall_at_most_s"]


def run_targets(models: str | Path = "models", repeats: int = 5, jobs: int = 2, map_repeats: int = 1,
                log: Callable[[str], None] = print) -> dict:
    """Measure every target and its baseline in one process; returns the report (see module doc)."""
    started = time.perf_counter()
    log(f"converged solution of {CASE}")
    ref = converged_solution(CASE, models, 10.0, log)
    report = {"case": CASE, "repeats": repeats, "floor": ref["floor"], "items": {}}
    for name, setting in SOLVES.items():
        row = measure(CASE, setting, ref, models, 10.0, repeats, 8.0, 1.0)
        report["items"][name] = row
        log(f"  {name}: x{row['realtime_ratio']:.2f} real time, peak err "
            f"{(row['errors'] or {}).get('peak_max')}, stats err {(row['errors'] or {}).get('stats_max')}")
    report["items"].update(stiff_items(models, repeats, log))
    report["items"].update(loom_friction_items(models, repeats, log))
    report["items"].update(loom_oiled_items(models, repeats, log))
    with tempfile.TemporaryDirectory(prefix="weftsim-targets-") as tmp:
        for engine in ("reference", "exudyn"):
            name = f"weftsim run {engine}, new process, 2 rev"
            report["items"][name] = cli_run(engine, models, repeats, Path(tmp))
            log(f"  {name}: {report['items'][name].get('wall_median_s')} s")
        for name, item in first_second(models, repeats, Path(tmp)).items():
            report["items"][name] = item
            log(f"  {name}: CPU {item.get('cpu_min_s')} s (least of {repeats}), wall {item.get('wall_median_s')} s")
        name = "121-cell map, 10 rev per cell"
        report["items"][name] = clearance_speed_map(models, jobs, map_repeats, Path(tmp))
        log(f"  {name}: {report['items'][name].get('wall_median_s')} s")
    for name, item in report["items"].items():
        item["target"] = TARGETS.get(name)
        item["met"] = _met(name, item)
    report["total_time_s"] = time.perf_counter() - started
    return report


def markdown(report: dict) -> str:
    """The targets table: what was measured, the target, met or not, and the ratio to the 0.1 baseline."""
    items = report["items"]
    base = {"reference": items.get("baseline: reference scipy DOP853 rtol 1e-9 (0.1 default)"),
            "exudyn": items.get("baseline: exudyn rigid_body h 2e-6 s (0.1 default)")}
    lines = [f"Case {report['case']}, medians of {report['repeats']} runs; converged-ensemble floor: peaks "
             f"{report['floor']['peak']:.1e}, statistics {report['floor']['stats']:.1e}.", "",
             "| item | measured | target | met | vs 0.1 default | peak error | statistics error |",
             "|---|---|---|---|---|---|---|"]  # fmt: skip
    for name, item in items.items():
        target = item.get("target") or {}
        if "ratio" in item or "realtime_ratio" not in item and "wall_median_s" not in item:
            measured = f"{item['ratio']:.2f}x" if "ratio" in item else item.get("status")
            met = {True: "yes", False: "**no**", None: ""}[item.get("met")]
            peak = item.get("peak_error")
            lines.append(f"| {name} | {measured} | {item.get('target_text', '')} | {met} | | "
                         f"{'-' if peak is None else f'{peak:.1e}'} | |")
            continue
        if "realtime_ratio" in item:
            measured = f"x{item['realtime_ratio']:.2f} real time"
            engine = item["engine"]
            speedup = (f"{item['realtime_ratio'] / base[engine]['realtime_ratio']:.1f}x faster"
                       if base.get(engine) and not name.startswith("baseline") else "")
            err = item.get("errors") or {}
            peak, stats = err.get("peak_max"), err.get("stats_max")
        else:
            measured = f"{item['wall_median_s']:.2f} s" if item.get("status") == "success" else item.get("status")
            if item.get("status") == "success" and "cpu_min_s" in item:
                measured += f" wall, {item['cpu_min_s']:.2f} s CPU"
            speedup, peak, stats = "", None, None
        goal = (f">= x{target['ratio_at_least']:g}" if "ratio_at_least" in target
                else f"<= {target['cpu_at_most_s']:g} s CPU" if "cpu_at_most_s" in target
                else f"<= {target['wall_at_most_s']:g} s" if target else "baseline" if name.startswith("baseline")
                else "")
        met = {True: "yes", False: "**no**", None: ""}[item.get("met")]
        fmt = (lambda v: "-" if v is None else f"{v:.1e}")
        lines.append(f"| {name} | {measured} | {goal} | {met} | {speedup} | {fmt(peak)} | {fmt(stats)} |")
    return "\n".join(lines) + "\n"


def write_targets(report: dict, outdir: str | Path, force: bool = False) -> list[Path]:
    """targets.json and targets.md into ``outdir``; returns the files."""
    from weftsim.bench.report import machine_info
    from weftsim.post.output import begin_directory, finish_directory, prepare_directory, write_json, write_text

    outdir = prepare_directory(outdir, force, kind="bench")
    begin_directory(outdir, {"kind": "bench", "mode": "targets"})
    report.setdefault("machine", machine_info())
    written = {"md": write_text(outdir / "targets.md", markdown(report)),
               "json": write_json(outdir / "targets.json", report)}
    finish_directory(outdir, written, {"kind": "bench", "mode": "targets"})
    return sorted(written.values())
