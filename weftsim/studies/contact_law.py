"""Contact-law study, like the paper's Fig. 7-9 (c = 0.01 mm, 500 rpm).

(a) K(delta) of the scene's law against penetration (paper Fig. 7), with the constant
    Lankarani-Nikravesh stiffness for reference;
(b) K(delta) at every solver step in contact along the last simulated revolution
    (paper Fig. 8: "contact stiffness with time");
(c) the damping coefficient D = xi K(delta) delta^n / v_imp (paper Eqs. 19, 23) at the
    same steps, against penetration (paper Fig. 9), with D(delta) of the law at fixed
    impact velocities.

K and D come from the contact-law library (:mod:`weftsim.joint.contact`) evaluated on the
per-step penetration and held impact velocity of a reference-engine run.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.studies import common

if TYPE_CHECKING:
    from collections.abc import Callable

    from weftsim.input.params import ClearanceJoint
    from weftsim.post.results import RunResult

SCENE = "paper/clearance_0p01mm_400rpm.toml"
SPEED_RPM = 500.0  # paper Fig. 7-9
REVOLUTIONS = 2.0  # the start-up revolution and one more, which is plotted
# What defines the study (common.study_overrides): the paper's case of Fig. 7-9, which its run's name says.
SETS = {"drive.speed_rpm": "the paper's Fig. 7-9 case is at 500 rpm",
        "joint_e.clearance_mm": "the paper's Fig. 7-9 case is at c = 0.01 mm"}
CURVE_POINTS = 601
CURVE_RANGE = 3.0  # stiffness curve up to 3 c (the paper's Fig. 7 spans ~0.02 mm at c = 0.01 mm)
FLATTENING_MM = 0.005  # paper: K(delta) flattens after 0.005 mm
DAMPING_LINEAR_MM = 0.015  # paper: D(delta) nonlinear up to ~0.015 mm, then closer to linear


def log_slope(function: Callable[[float], float], x: float, h: float = 1e-4) -> float:
    """d ln f / d ln x at x by a central difference in ln x (relative step h)."""
    return float((math.log(function(x * (1 + h))) - math.log(function(x * (1 - h)))) /
                 (math.log1p(h) - math.log1p(-h)))


def stiffness_curve(joint: ClearanceJoint, points: int = CURVE_POINTS, extent: float = CURVE_RANGE) -> dict:
    """K(delta) of ``joint``'s law on 0..extent x c, and the numbers quoted against the paper."""
    from dataclasses import replace

    from weftsim.joint.contact import lankarani_nikravesh_stiffness, make_law

    law = make_law(joint)
    c = joint.clearance
    penetration = np.linspace(0.0, extent * c, points)
    stiffness = np.asarray(law.stiffness(penetration), dtype=float)
    ln_joint = replace(joint, law="lankarani_nikravesh")
    at_flattening = float(law.stiffness(FLATTENING_MM * 1e-3))
    far = float(law.stiffness(1e3 * c))  # the plateau: K(delta >> c)
    stiff = lambda d: float(law.stiffness(d))  # noqa: E731
    damp = lambda d: float(law.damping(d, 1.0))  # noqa: E731  (D at fixed v_imp: v_imp only scales it)
    return {
        "law": law.name,
        "exponent": law.exponent,
        "hysteresis": law.hysteresis,
        "clearance_mm": c * 1e3,
        "penetration_mm": penetration * 1e3,
        "stiffness": stiffness,
        "stiffness_constant": lankarani_nikravesh_stiffness(ln_joint),
        "numbers": {
            "stiffness_at_0p005mm": at_flattening,
            "stiffness_plateau": far,
            "stiffness_at_0p005mm_over_plateau": at_flattening / far,
            "stiffness_at_end_over_plateau": float(stiffness[-1] / far),
            "stiffness_log_slope": {f"{d:g}": log_slope(stiff, d * 1e-3) for d in (0.0005, 0.005, 0.015, 0.03)},
            "damping_log_slope": {f"{d:g}": log_slope(damp, d * 1e-3) for d in (0.0005, 0.005, 0.015, 0.03)},
        },
    }


COMPARISON_LOADS_KN = (1.0, 10.0, 50.0)
FE_CHECKED = "cylindrical"  # the law checked against the FE model of the pin in its bushing (issue 37)


def law_comparison(joint: ClearanceJoint, loads_kn=COMPARISON_LOADS_KN) -> list[dict]:
    """Every law of the library on ``joint`` (its own clearance, pin, bushing and materials): the approach
    delta at which its elastic force carries each load, and its ratio to the FE-checked law's
    (:data:`FE_CHECKED`, within 10 % of the plane-strain FE model: docs/physics.md, "The cylindrical law").
    A law the joint cannot build (the cylindrical law without ``bushing_wall``) gets its reason instead."""
    from dataclasses import replace

    from scipy.optimize import brentq

    from weftsim.joint.contact import LAWS, make_law

    def approach(law, force):
        return brentq(lambda d: float(law.elastic_force(d)) - force, 1e-14, 1.0, xtol=1e-16, rtol=1e-12)

    rows: list[dict[str, Any]] = []
    checked: list[float] | None = None
    for name in sorted(LAWS, key=lambda n: (n != FE_CHECKED, n)):
        try:
            law = make_law(replace(joint, law=name))
        except ValueError as err:
            rows.append({"law": name, "error": str(err)})
            continue
        row: dict[str, Any] = {"law": name, "fe_checked": name == FE_CHECKED, "exponent": law.exponent,
                               "approach_um": [approach(law, f * 1e3) * 1e6 for f in loads_kn]}
        if name == FE_CHECKED:
            checked = row["approach_um"]
        rows.append(row)
    for row in rows:
        if checked is not None and "approach_um" in row:
            row["over_fe_checked"] = [a / b for a, b in zip(row["approach_um"], checked)]
    return rows


def contact_steps(result: RunResult, revolution: int) -> dict[str, np.ndarray]:
    """Steps in contact of one revolution with K(delta) and D(delta, v_imp) from the scene's law."""
    from weftsim.joint.contact import make_law

    law = make_law(result.scene.joint)
    data = common.revolution_steps(result, revolution)
    keep = (data["in_contact"] > 0.5) & (data["penetration_m"] > 0.0)
    penetration = data["penetration_m"][keep]
    impact = data["impact_velocity_m_s"][keep]
    return {
        "time_s": data["time_s"][keep],
        "crank_angle_deg": data["crank_angle_deg"][keep],
        "penetration_mm": penetration * 1e3,
        "impact_velocity_m_s": impact,
        "stiffness": np.asarray(law.stiffness(penetration), dtype=float),
        "damping": np.asarray(law.damping(penetration, impact), dtype=float),
        "contact_force_N": data["contact_force_N"][keep],
    }


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the contact-law study into ``outdir``; returns what ``contact-law.json`` holds.

    ``overrides``: scene keys (file units) applied to its run, except its speed and clearance (:data:`SETS`).
    ``scene``: the scene file or bundled name its cases run on (default: the paper's reference, ``models/``).
    """
    from weftsim.joint.contact import make_law
    from weftsim.post.output import write_csv, write_figure, write_json
    from weftsim.studies.figures import contact_law_panels

    overrides = common.study_overrides("contact-law", SETS, revolutions, REVOLUTIONS, overrides)
    source, base = scene, common.base_scene(models, scene, overrides)
    outdir = common.open_directory(outdir, force, base)
    study_scene = common.load(models, SCENE, {"drive.speed_rpm": SPEED_RPM, "name": "contact_law_0p01mm_500rpm",
                                        **overrides}, source)
    curve = stiffness_curve(study_scene.joint)
    result = common.solve(study_scene, "reference", progress=progress)
    from weftsim.post.analysis import complete_revolutions

    n = complete_revolutions(result)
    revolution = max(n - 1, 0)
    steps = contact_steps(result, revolution)
    law = make_law(study_scene.joint)
    written = {
        "curve": write_csv(outdir / "contact-law-stiffness.csv", {
            "penetration_mm": curve["penetration_mm"],
            "stiffness_N_m1p5": curve["stiffness"],
            "stiffness_lankarani_nikravesh_N_m1p5": np.full_like(curve["stiffness"], curve["stiffness_constant"]),
        }),
        "steps": write_csv(outdir / "contact-law-revolution.csv", {
            "time_s": steps["time_s"], "crank_angle_deg": steps["crank_angle_deg"],
            "penetration_mm": steps["penetration_mm"], "impact_velocity_m_s": steps["impact_velocity_m_s"],
            "stiffness_N_m1p5": steps["stiffness"], "damping_N_s_m": steps["damping"],
            "contact_force_N": steps["contact_force_N"]}),
    }
    law_lines = []
    if steps["impact_velocity_m_s"].size:
        delta = np.linspace(0.0, max(float(steps["penetration_mm"].max()), CURVE_RANGE * curve["clearance_mm"]), 300)
        for q, what in ((100, "largest"), (50, "median")):
            v = float(np.percentile(steps["impact_velocity_m_s"], q))
            law_lines.append((f"law at v_imp = {v:.3g} m/s ({what})", delta, law.damping(delta * 1e-3, v)))
    rpm = common.speed_rpm(study_scene)
    title = (f"contact law {law.name}, c = {curve['clearance_mm']:g} mm, {rpm:g} rpm "
             f"(revolution {revolution + 1} of {n}, reference engine)" + common.title_note(base, overrides))
    written["figure"] = write_figure(outdir / "study-contact-law.png",
                                     contact_law_panels(curve, steps, law_lines, title))
    in_contact = {}
    if steps["stiffness"].size:
        data = common.revolution_steps(result, revolution)
        from weftsim.post.analysis import time_weights

        w = time_weights(data["time_s"])
        in_contact = {
            "steps_in_contact": int(steps["stiffness"].size),
            "time_fraction_in_contact": float(np.dot(w, data["in_contact"] > 0.5) / w.sum()),
            "stiffness_min": float(steps["stiffness"].min()),
            "stiffness_median": float(np.median(steps["stiffness"])),
            "stiffness_max": float(steps["stiffness"].max()),
            "penetration_max_mm": float(steps["penetration_mm"].max()),
            "damping_min": float(steps["damping"].min()),
            "damping_max": float(steps["damping"].max()),
            "impact_velocity_min_m_s": float(steps["impact_velocity_m_s"].min()),
            "impact_velocity_max_m_s": float(steps["impact_velocity_m_s"].max()),
        }
    report = {
        "study": "contact-law",
        **common.record(base, overrides),
        "scene": study_scene.name,
        "clearance_mm": curve["clearance_mm"],
        "speed_rpm": rpm,
        "law": curve["law"],
        "hysteresis": curve["hysteresis"],
        "exponent": curve["exponent"],
        "stiffness_lankarani_nikravesh": curve["stiffness_constant"],
        "curve": curve["numbers"],
        "plotted_revolution": revolution + 1,
        "laws_on_the_scene": {"scene": base.name, "clearance_mm": base.joint.clearance * 1e3,
                              "loads_kN": list(COMPARISON_LOADS_KN), "laws": law_comparison(base.joint)},
        "revolution": in_contact,
        "run": common.run_metrics(result),
        "files": sorted(p.name for p in written.values()),
    }
    written["json"] = write_json(outdir / "contact-law.json", report)
    common.finish(outdir, written, "contact-law", base)
    return report


def format_report(report: dict) -> str:
    """The lines ``weftsim study contact-law`` prints."""
    c, r = report["curve"], report.get("revolution") or {}
    lines = [
        f"contact-law study: {report['law']}, c = {report['clearance_mm']:g} mm, {report['speed_rpm']:g} rpm",
        f"  K(0.005 mm) = {c['stiffness_at_0p005mm']:.4g} N/m^1.5 = {c['stiffness_at_0p005mm_over_plateau']:.3f} "
        f"of the plateau K(delta >> c) = {c['stiffness_plateau']:.4g}",
        "  d ln K / d ln delta at " + ", ".join(f"{k} mm: {v:.3f}" for k, v in c["stiffness_log_slope"].items()),
        "  d ln D / d ln delta at " + ", ".join(f"{k} mm: {v:.3f}" for k, v in c["damping_log_slope"].items()),
    ]
    on = report.get("laws_on_the_scene")
    if on:
        loads = " / ".join(f"{f:g}" for f in on["loads_kN"])
        lines.append(f"  every law on {on['scene']}'s joint (c = {on['clearance_mm']:g} mm): approach at {loads} kN, "
                     f"and against the FE-checked {FE_CHECKED}")
        for row in on["laws"]:
            if "error" in row:
                lines.append(f"    {row['law']:<20} not on this joint: {row['error']}")
                continue
            um = " / ".join(f"{a:.3g}" for a in row["approach_um"])
            ratio = (" x " + " / ".join(f"{x:.2f}" for x in row["over_fe_checked"])) if "over_fe_checked" in row else ""
            mark = "  (FE-checked)" if row["fe_checked"] else ""
            lines.append(f"    {row['law']:<20} {um} um{ratio}{mark}")
    if r:
        lines.append(f"  revolution {report['plotted_revolution']}: in contact "
                     f"{100 * r['time_fraction_in_contact']:.1f}% of the time, "
                     f"K {r['stiffness_min']:.3g} .. {r['stiffness_max']:.3g} N/m^1.5, "
                     f"delta up to {r['penetration_max_mm']:.4g} mm, D {r['damping_min']:.3g} .. "
                     f"{r['damping_max']:.3g} N s/m")
    return "\n".join(lines)
