"""Clearance study, like the paper's Fig. 12: c = 0.01, 0.25, 0.50 mm at 400 rpm (reference engine).

The curves of the last revolution are overlaid as in the paper (an illustration: after
the first impacts the impact sequence is not reproducible, docs/physics.md section 6); the
clearance trend is read from the reproducible numbers of each run (first-revolution
peaks, statistics over revolutions 2..N), with the ideal joint as the baseline.

The paper also says the acceleration oscillates at high frequency "near the maximum
acceleration value, that is near the maximum value and zero value of the velocity";
:func:`acceleration_deviation` measures where the clearance acceleration departs from the
ideal one, per crank-angle bin, to check that statement.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.studies import common

if TYPE_CHECKING:
    from weftsim.input.params import Geometry
    from weftsim.post.results import RunResult

IDEAL_SCENE = "ideal.toml"
SCENES = {0.01: "paper/clearance_0p01mm_400rpm.toml", 0.25: "paper/clearance_0p25mm_400rpm.toml",
          0.50: "paper/clearance_0p50mm_400rpm.toml"}
REVOLUTIONS = 10.0  # 9 revolutions after the start-up one for the statistics (~10 s each)
SETS = {"joint_e.clearance_mm": "it varies the clearance: 0 (ideal), 0.01, 0.25, 0.50 mm"}  # common.study_overrides
BIN_DEG = 10.0
COLOURS = {0.01: "tab:blue", 0.25: "tab:orange", 0.50: "tab:red"}


def ideal_features(geometry: Geometry, omega: float, points: int = 36001) -> dict[str, list[float]]:
    """Crank angles (deg) of the ideal rapier acceleration extremes, velocity extremes and velocity zeros."""
    from weftsim.mechanism.kinematics import rapier_motion

    theta = np.linspace(0.0, 2.0 * math.pi, points)
    _, v, a = rapier_motion(theta, omega, geometry)
    deg = np.degrees(theta)
    crossings = np.flatnonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)
    zeros = [float(deg[i] - v[i] * (deg[i + 1] - deg[i]) / (v[i + 1] - v[i])) for i in crossings]
    if abs(v[0]) < 1e-9 * np.abs(v).max():
        zeros = [0.0] + zeros
    return {
        "acceleration_max_deg": [float(deg[np.argmax(a)])],
        "acceleration_min_deg": [float(deg[np.argmin(a)])],
        "velocity_extremes_deg": [float(deg[np.argmax(v)]), float(deg[np.argmin(v)])],
        "velocity_zeros_deg": sorted(zeros),
    }


def acceleration_deviation(result: RunResult, bin_deg: float = BIN_DEG,
                           skip_revolutions: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Time-weighted RMS of a - a_ideal per crank-angle bin over revolutions after ``skip_revolutions``.

    Returns
    -------
    centres : ndarray
        Bin centres, deg.
    rms : ndarray
        m/s^2 (nan for empty bins).
    """
    from weftsim.post.analysis import complete_revolutions, time_weights
    from weftsim.mechanism.kinematics import rapier_motion

    n = complete_revolutions(result)
    edges = np.arange(0.0, 360.0 + 0.5 * bin_deg, bin_deg)
    centres = 0.5 * (edges[1:] + edges[:-1])
    if n <= skip_revolutions:
        return centres, np.full(centres.size, np.nan)
    period = result.scene.drive.period
    t = result.steps["time_s"]
    keep = (t >= skip_revolutions * period - 1e-12) & (t <= n * period + 1e-12)
    angle = result.steps["crank_angle_deg"][keep]
    _, _, ideal = rapier_motion(np.radians(angle), result.scene.drive.speed, result.scene.geometry)
    square = (result.steps["rapier_acceleration_m_s2"][keep] - ideal) ** 2
    w = time_weights(t[keep])
    index = np.clip(np.digitize(np.mod(angle, 360.0), edges) - 1, 0, centres.size - 1)
    weight = np.bincount(index, w, centres.size)
    total = np.bincount(index, w * square, centres.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        return centres, np.sqrt(total / weight)


def nearest_feature(angle: float, features: dict[str, list[float]]) -> tuple[str, float]:
    """The ideal-motion feature closest to ``angle`` (deg, on the circle) and its distance."""
    best = ("", math.inf)
    for name, angles in features.items():
        for a in angles:
            distance = abs((angle - a + 180.0) % 360.0 - 180.0)
            if distance < best[1]:
                best = (name, distance)
    return best


def trend_row(metrics: dict, ideal: dict) -> dict:
    """The clearance-trend numbers of one run, with the ideal run as baseline."""
    first, stats = metrics["first_revolution"], metrics["statistics"] or {}
    ideal_stats = ideal["statistics"] or {}

    def stat(channel, field, source=stats):
        return source.get(channel, {}).get(field)

    row = {
        "clearance_mm": metrics["clearance_mm"],
        "first_contact_crank_angle_deg": metrics["first_contact_crank_angle_deg"],
        "first_revolution_contact_force_max_N": first["contact_force_N"]["max"],
        "first_revolution_acceleration_peak_m_s2": common.magnitude(first["rapier_acceleration_m_s2"]),
        "first_revolution_torque_peak_Nm": common.magnitude(first["driving_torque_Nm"]),
        "acceleration_rms_m_s2": stat("rapier_acceleration_m_s2", "rms"),
        "acceleration_p99_abs_m_s2": stat("rapier_acceleration_m_s2", "p99_abs"),
        "torque_rms_Nm": stat("driving_torque_Nm", "rms"),
        "torque_p99_abs_Nm": stat("driving_torque_Nm", "p99_abs"),
        "contact_force_mean_N": stat("contact_force_N", "mean"),
        "contact_force_p99_N": stat("contact_force_N", "p99"),
    }
    for channel, short in (("rapier_displacement_m", "displacement"), ("rapier_velocity_m_s", "velocity")):
        for field in ("min", "max"):
            ours, base = stat(channel, field), stat(channel, field, ideal_stats)
            row[f"{short}_{field}_change_vs_ideal"] = None if ours is None or not base else ours / base - 1.0
    return row


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the clearance study into ``outdir``; returns what ``clearance.json`` holds.

    ``overrides``: scene keys (file units) applied to every run, except the clearance (:data:`SETS`).
    ``scene``: the scene file or bundled name its cases run on (default: the paper's reference, ``models/``).
    """
    from weftsim.post.output import write_figure, write_json
    from weftsim.studies.figures import channel_panels, deviation_panel, trend_panels

    overrides = common.study_overrides("clearance", SETS, revolutions, REVOLUTIONS, overrides)
    base = common.base_scene(models, scene, overrides)
    outdir = common.open_directory(outdir, force, base)
    note = common.title_note(base, overrides)
    ideal_result = common.solve(common.load(models, IDEAL_SCENE, overrides, scene), progress=progress)
    ideal = common.run_metrics(ideal_result)
    results = {c: common.solve(common.load(models, name, overrides, scene), progress=progress)
               for c, name in SCENES.items()}
    metrics = {c: common.run_metrics(r) for c, r in results.items()}
    written: dict[str, Any] = {}
    curves: list[tuple[str, Any, dict[str, Any]]] = []
    deviations: list[tuple[str, Any, dict[str, Any]]] = []
    last = max(ideal["revolutions"] - 1, 0)
    ideal_curve = common.revolution_steps(ideal_result, last)
    written["curves-ideal"] = common.write_curves(outdir, "clearance-curves-ideal", ideal_curve)
    features = ideal_features(ideal_result.scene.geometry, ideal_result.scene.drive.speed)
    deviation_rows = {}
    for c, result in results.items():
        n = metrics[c]["revolutions"]
        data = common.revolution_steps(result, max(n - 1, 0))
        written[f"curves-{c:g}"] = common.write_curves(outdir, f"clearance-curves-{c:g}mm", data)
        curves.append((f"c = {c:g} mm", data, {"color": COLOURS[c]}))
        centres, rms = acceleration_deviation(result)
        deviations.append((f"c = {c:g} mm", rms, {"color": COLOURS[c]}))
        finite = np.isfinite(rms)
        top = [] if not finite.any() else [float(centres[i]) for i in np.argsort(np.where(finite, rms, -1))[::-1][:3]]
        deviation_rows[f"{c:g}"] = {
            "bin_centres_deg": centres.tolist(), "rms_m_s2": rms.tolist(),
            "largest_bins_deg": top,
            "nearest_features": [dict(zip(("feature", "distance_deg"), nearest_feature(a, features))) for a in top],
        }
    curves.append(("ideal joint", ideal_curve, {"color": "k", "ls": "--", "lw": 0.9}))
    rpm = common.speed_rpm(ideal_result.scene)
    written["figure"] = write_figure(outdir / "study-clearance.png", channel_panels(
        curves, f"clearance study at {rpm:g} rpm, reference engine, last of "
                f"{metrics[0.25]['revolutions']} revolutions (cf. paper Fig. 12)" + note))
    rows = [trend_row(metrics[c], ideal) for c in SCENES]
    x = list(SCENES)
    def lines(*pairs):
        return [(label, [r[key] for r in rows]) for label, key in pairs]

    written["trend"] = write_figure(outdir / "study-clearance-trend.png", trend_panels(x, "radial clearance c [mm]", [
        ("rapier acceleration [m/s²]", lines(("max |a|, revolution 1", "first_revolution_acceleration_peak_m_s2"),
                                             ("99th pct |a|, rev. 2..N", "acceleration_p99_abs_m_s2"),
                                             ("RMS, rev. 2..N", "acceleration_rms_m_s2"))),
        ("driving torque [N·m]", lines(("max |T|, revolution 1", "first_revolution_torque_peak_Nm"),
                                       ("99th pct |T|, rev. 2..N", "torque_p99_abs_Nm"),
                                       ("RMS, rev. 2..N", "torque_rms_Nm"))),
        ("contact force at E [N]", lines(("max, revolution 1", "first_revolution_contact_force_max_N"),
                                         ("99th percentile, rev. 2..N", "contact_force_p99_N"),
                                         ("mean, rev. 2..N", "contact_force_mean_N"))),
    ], f"clearance trend at {rpm:g} rpm (reproducible quantities; reference engine)" + note, x_ticks=x))
    markers = [("ideal a extremes", features["acceleration_max_deg"] + features["acceleration_min_deg"],
                {"color": "k", "ls": "-", "lw": 0.8}),
               ("ideal v extremes", features["velocity_extremes_deg"], {"color": "0.4", "ls": "--", "lw": 0.8}),
               ("ideal v = 0", features["velocity_zeros_deg"], {"color": "0.4", "ls": ":", "lw": 1.0})]
    written["deviation"] = write_figure(outdir / "study-clearance-deviation.png", deviation_panel(
        np.arange(BIN_DEG / 2, 360.0, BIN_DEG), deviations, markers,
        f"where the clearance acceleration departs from the ideal one ({rpm:g} rpm, revolutions 2..N)" + note))
    report = {
        "study": "clearance",
        **common.record(base, overrides),
        "speed_rpm": rpm,
        "revolutions": metrics[0.25]["revolutions"],
        "ideal": ideal,
        "runs": {f"{c:g}": metrics[c] for c in SCENES},
        "trend": rows,
        "ideal_features_deg": features,
        "acceleration_deviation": deviation_rows,
        "files": sorted(p.name for p in written.values()) + ["clearance.json"],
    }
    written["json"] = write_json(outdir / "clearance.json", report)
    common.finish(outdir, written, "clearance", base)
    return report


def format_report(report: dict) -> str:
    """The table ``weftsim study clearance`` prints."""
    lines = [f"clearance study at {report['speed_rpm']:g} rpm, {report['revolutions']} revolutions (reference engine)",
             f"{'c [mm]':>7s} {'1st contact':>11s} {'F rev1 max':>11s} {'|a| rev1':>9s} {'|T| rev1':>9s} "
             f"{'a RMS':>8s} {'a p99|.|':>9s} {'T RMS':>8s} {'T p99|.|':>9s} {'F mean':>9s} {'F p99':>9s} "
             f"{'s max chg':>9s} {'v max chg':>9s}"]

    def f(value, spec):
        return format(value, spec) if value is not None else "-"

    ideal = report["ideal"]["statistics"] or {}
    lines.append(f"{'ideal':>7s} {'-':>11s} {'-':>11s} "
                 f"{f(common.magnitude(report['ideal']['first_revolution']['rapier_acceleration_m_s2']), '9.1f')} "
                 f"{f(common.magnitude(report['ideal']['first_revolution']['driving_torque_Nm']), '9.1f')} "
                 f"{f(ideal.get('rapier_acceleration_m_s2', {}).get('rms'), '8.1f')}")
    for r in report["trend"]:
        lines.append(
            f"{r['clearance_mm']:7.2f} {f(r['first_contact_crank_angle_deg'], '11.3f')} "
            f"{r['first_revolution_contact_force_max_N']:11.4g} {r['first_revolution_acceleration_peak_m_s2']:9.1f} "
            f"{r['first_revolution_torque_peak_Nm']:9.1f} {f(r['acceleration_rms_m_s2'], '8.1f')} "
            f"{f(r['acceleration_p99_abs_m_s2'], '9.1f')} {f(r['torque_rms_Nm'], '8.1f')} "
            f"{f(r['torque_p99_abs_Nm'], '9.1f')} {f(r['contact_force_mean_N'], '9.4g')} "
            f"{f(r['contact_force_p99_N'], '9.4g')} {f(r['displacement_max_change_vs_ideal'], '+9.1e')} "
            f"{f(r['velocity_max_change_vs_ideal'], '+9.1e')}")
    for c, row in report["acceleration_deviation"].items():
        near = ", ".join(f"{a:g} deg ({n['feature']}, {n['distance_deg']:.0f} deg away)"
                         for a, n in zip(row["largest_bins_deg"], row["nearest_features"]))
        lines.append(f"  c = {c} mm: largest |a - a_ideal| in bins at {near}")
    return "\n".join(lines)
