"""Shared parts of the studies: scene files, engine runs, the reproducible numbers of a run.

docs/physics.md section 6: after the first impacts the impact sequence depends on round-off,
step and tolerance, so each run is summarised by quantities that do not:

- ``first_revolution``: min and max of each peak channel over revolution 1 (the start-up
  impact from the centred journal dominates them);
- ``statistics``: time-weighted mean, RMS and percentiles over revolutions 2..N;
- ``last_revolution``: min and max over the last revolution, reported as an illustration
  (the paper's single-cycle curves), not as a reproducible number.
"""

from __future__ import annotations

import logging
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import SimulationFailed, StudyError  # noqa: F401 (re-exported: weftsim.studies)

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult

log = logging.getLogger(__name__)

RPM = 60.0 / (2.0 * math.pi)  # rad/s -> rpm


def scene_path(models: str | Path, name: str) -> Path:
    """``models/<name>``, with an error that says where the scene files are expected."""
    path = Path(models) / name
    if not path.is_file():
        raise StudyError(f"scene file {path} not found; run from the repository root or pass the "
                         "models directory (--models DIR)")
    return path


REFERENCE = "reference.toml"  # the scene every study's files extend (models/paper/*.toml, ideal.toml)
# The keys a study's scene file sets on the reference scene, shown in the names of its runs on another scene.
NAMED_KEYS = {"joint_e.clearance_mm": "c{:g}mm", "drive.speed_rpm": "{:g}rpm"}


def own_keys(path: Path) -> dict:
    """The keys a scene file gives itself (not those of the scene it extends), ``extends``, ``name`` and
    ``description`` left out: what a study's case changes on the scene it is run on."""
    from weftsim.input.scene import TOP_LEVEL, _flatten, _read_toml

    return {k: v for k, v in _flatten(_read_toml(path), str(path)).items() if k not in TOP_LEVEL}


def load(models: str | Path, name: str, overrides: dict | None = None, base: str | Path | None = None) -> Scene:
    """Load ``models/<name>`` with file-unit overrides (e.g. ``{"drive.revolutions": 10}``).

    With ``base`` (a scene file or bundled name: ``weftsim study NAME SCENE``) the case runs on that scene
    instead: ``base`` with the keys ``models/<name>`` sets itself (:func:`own_keys`: the clearance of a
    clearance case, the speed of a speed case), then ``overrides``; it is named after ``base`` and those keys.
    """
    from weftsim.input.scene import load_scene

    path = scene_path(models, name)
    if base is None:
        return load_scene(path, overrides)
    case = own_keys(path)
    base_name = load_scene(base).name
    suffix = "_".join(form.format(case[key]) for key, form in NAMED_KEYS.items() if key in case)
    return load_scene(base, {**case, "name": f"{base_name}_{suffix}" if suffix else base_name, **(overrides or {})})


def base_scene(models: str | Path, base: str | Path | None, overrides: dict) -> Scene:
    """The scene a study runs its cases on, resolved with ``overrides`` (``models/reference.toml`` by default):
    what its output directory records (:mod:`weftsim.post.record`) and refuses to mix with another."""
    from weftsim.input.scene import load_scene

    return load_scene(scene_path(models, REFERENCE) if base is None else base, overrides)


def open_directory(outdir: str | Path, force: bool, scene: Scene) -> Path:
    """:func:`weftsim.post.output.prepare_directory` for a study of ``scene`` (a directory holding a study of
    another scene or other overrides is refused unless ``force``)."""
    from weftsim.post.output import prepare_directory

    return prepare_directory(outdir, force, scene, kind="study")


def record(scene: Scene, overrides: dict) -> dict:
    """What a study's JSON records of how it was made: the scene its cases run on, the overrides given
    (``--set`` and the shorthands, file units, the revolutions included) and the command line."""
    from weftsim.post.record import command_line

    return {"base_scene": scene.name, "overrides": dict(overrides), "command": command_line()}


def title_note(scene: Scene, overrides: dict) -> str:
    """A second title line naming the scene and the overrides when they are not the paper's reference."""
    shown = [f"{key} = {value:g}" if isinstance(value, float) else f"{key} = {value}"
             for key, value in overrides.items() if key != "drive.revolutions"]
    if scene.name == "reference" and not shown:
        return ""
    return "\n(scene " + scene.name + ("; " + ", ".join(shown) if shown else "") + ")"


def finish(outdir: Path, written: dict, study: str, scene: Scene) -> None:
    """Write ``scene.toml`` (the resolved scene the cases run on) and the manifest, last."""
    from weftsim.post.output import finish_directory, write_text
    from weftsim.post.record import SCENE_FILE, provenance, scene_toml

    written["scene"] = write_text(outdir / SCENE_FILE, scene_toml(scene))
    finish_directory(outdir, written, {"kind": "study", "study": study, **provenance(scene)})


def wrote_lines(outdir: Path, report: dict) -> list[str]:
    """``  wrote <path>`` per file of a study, as ``weftsim run`` reports its files."""
    from weftsim.post.record import SCENE_FILE

    return [f"  wrote {Path(outdir) / name}" for name in sorted(set(report.get("files", [])) | {SCENE_FILE})]


def _quiet(text: str) -> None:
    """A study case's before-run warnings: kept in its result (``plausibility["checks"]``), not printed per case."""


def solve(scene: Scene, engine: str = "reference", label: str | None = None, progress: bool = True) -> RunResult:
    """Run one engine on a scene (progress on stderr for long runs); a failed run raises SimulationFailed."""
    from weftsim.engines import simulate
    from weftsim.engines import names
    from weftsim.checks.progress import Progress

    if engine not in names():
        raise StudyError(f"engine must be one of {', '.join(names())}, got {engine!r}")
    reporter = Progress(label or f"{engine} {scene.name}") if progress else None
    start = time.perf_counter()
    try:
        # the one door: before-run checks (their warnings are the study's result.plausibility["checks"]),
        # the engine's solve, the vetting
        result = simulate(scene, engine, progress=reporter, on_warning=_quiet)
    finally:
        if reporter is not None:
            reporter.close()
    log.info("%s %s: %s in %.1f s", engine, scene.name, result.status, time.perf_counter() - start)
    if not result.ok:
        raise SimulationFailed(f"{engine} engine failed on scene {scene.name}: {result.message}")
    return result


def speed_rpm(scene: Scene) -> float:
    return round(scene.drive.speed * RPM, 9)


def clearance_mm(scene: Scene) -> float:
    return round(scene.joint.clearance * 1e3, 12)


def percentile(result: RunResult, channel: str, q: float, skip_revolutions: int = 1) -> float | None:
    """Time-weighted percentile q of a channel over the whole revolutions after ``skip_revolutions``."""
    from weftsim.post.analysis import complete_revolutions, time_weights, weighted_percentile

    n = complete_revolutions(result)
    if n <= skip_revolutions:
        return None
    period = result.scene.drive.period
    t = result.steps["time_s"]
    keep = (t >= skip_revolutions * period - 1e-12) & (t <= n * period + 1e-12)
    return weighted_percentile(result.steps[channel][keep], time_weights(t[keep]), q)


def run_metrics(result: RunResult) -> dict:
    """The numbers of one run that the studies and the report use (JSON-ready).

    ``statistics`` (revolutions 2..N) adds ``p1`` (1st percentile) to the fields of
    :func:`weftsim.post.analysis.channel_statistics`; it is None for runs of fewer than 2 revolutions.
    ``first_revolution`` and ``last_revolution`` are those of the part run when the run is
    shorter than one revolution.
    """
    from weftsim.post.analysis import complete_revolutions, peaks, statistics

    n = complete_revolutions(result)
    stats = statistics(result)
    if stats is not None:
        for channel, values in stats.items():
            values["p1"] = percentile(result, channel, 1.0)  # type: ignore[assignment]  # None: too short
    return {
        "scene": result.scene.name,
        "engine": result.engine,
        "clearance_mm": clearance_mm(result.scene),
        "speed_rpm": speed_rpm(result.scene),
        "law": result.scene.joint.law,
        "revolutions": n,
        "wall_time_s": result.wall_time_s,
        "first_contact_crank_angle_deg": result.first_contact_angle_deg,
        # A run shorter than one revolution: its peaks so far (reduced settings in tests).
        "first_revolution": peaks(result, 0) if result.steps["time_s"].size else None,
        "last_revolution": peaks(result, max(n - 1, 0)) if result.steps["time_s"].size else None,
        "statistics": stats,
    }


def magnitude(peak: dict | None) -> float | None:
    """Largest magnitude max(|min|, |max|) of a {min, max} peak entry."""
    if peak is None:
        return None
    return max(abs(peak["min"]), abs(peak["max"]))


def ratio(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or b == 0:
        return None
    return a / b


def revolution_steps(result: RunResult, revolution: int) -> dict[str, np.ndarray]:
    """Per-step channels of one (0-based) revolution, crank angle folded to 0..360 deg."""
    period = result.scene.drive.period
    t = result.steps["time_s"]
    keep = (t >= revolution * period - 1e-12) & (t <= (revolution + 1) * period + 1e-12)
    data = {name: values[keep] for name, values in result.steps.items()}
    data["crank_angle_deg"] = data["crank_angle_deg"] - 360.0 * revolution
    return data


CURVE_CHANNELS = ("time_s", "crank_angle_deg", "rapier_displacement_m", "rapier_velocity_m_s",
                  "rapier_acceleration_m_s2", "driving_torque_Nm", "contact_force_N", "penetration_m")


def write_curves(outdir: Path, name: str, data: dict[str, np.ndarray]) -> Path:
    """The per-step curves a figure shows, as ``<name>.csv`` (crank angle folded to 0..360 deg)."""
    from weftsim.post.output import write_csv

    return write_csv(Path(outdir) / f"{name}.csv", {channel: data[channel] for channel in CURVE_CHANNELS})


def revolutions_override(revolutions: float | None, default: float) -> dict:
    value = default if revolutions is None else revolutions
    if not (value > 0 and math.isfinite(value)):
        raise StudyError(f"revolutions must be > 0, got {value}")
    return {"drive.revolutions": value}


def _dotted(key: str) -> str:
    """A scene key as its full dotted path (``clearance_mm`` -> ``joint_e.clearance_mm``), else as given
    (an unknown key is then reported by the scene loader)."""
    from weftsim.errors import SweepError
    from weftsim.sweep.grid import resolve_key

    try:
        return resolve_key(key).path
    except SweepError:
        return key


def study_overrides(study: str, sets: dict[str, str], revolutions: float | None, default: float,
                    overrides: dict | None = None) -> dict:
    """The scene overrides of every run of a study: the user's ``overrides`` and the revolutions.

    Parameters
    ----------
    study : str
        The study's name, for the messages.
    sets : dict
        The keys the study sets itself (what it varies or what defines it) -> why; overriding one is
        refused, as is ``name`` (each study names its runs).
    revolutions : float or None
        Crank revolutions per run (``drive.revolutions``; None: ``default``, or the value in ``overrides``).
    overrides : dict, optional
        Scene keys in file units (dotted keys, or their last part where unique), applied to every scene.

    Raises
    ------
    StudyError
        A key the study sets itself, or the revolutions given twice.
    """
    given = {_dotted(key): value for key, value in (overrides or {}).items()}
    for key in given:
        if key == "name":
            raise StudyError(f"the {study} study names its own runs; leave 'name' out of the overrides")
        if key in sets:
            raise StudyError(f"the {study} study sets {key} itself ({sets[key]}); do not override it "
                             "(neither --set nor its shorthand flag)")
        if key == "joint_f.clearance_mm" and given[key]:
            # The studies are the paper's figures, of the clearance at E: their tables and figures hold
            # joint E's contact alone, and a clearance at F would be left out of them (issue 24).
            raise StudyError(f"the {study} study is of the clearance at E (the paper's figures); a clearance at F "
                             "is not in its tables or figures: sweep it instead (weftsim sweep clearance_f --vary "
                             "joint_f.clearance_mm=...), whose table carries each joint")
        if ".wear." in key:
            raise StudyError(f"key '{key}' is read by `weftsim wear` only: the {study} study does not depend on it")
    if "drive.revolutions" in given:
        if revolutions is not None:
            raise StudyError("the revolutions are given twice (as revolutions and as drive.revolutions); "
                             "give them once")
        revolutions = given.pop("drive.revolutions")
    return {**given, **revolutions_override(revolutions, default)}
