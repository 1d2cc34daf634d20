"""Loads at joint E of the `loom` and the `reference` mechanism: the table of docs/physics.md ("The loom mechanism").

``PYTHONPATH=. python scripts/loom_loads_table.py [--engine exudyn] [--out docs/data/loom-loads.csv]``

For each mechanism, crank speed (300, 600, 800 rpm) and radial clearance at E (0.02, 0.05, 0.1,
0.25 mm), one run of two revolutions, friction off (dry, as the scenes).  Revolution 1 starts from the
centred journal; its peaks hold the start-up impact.  The table gives revolution 2 (the running
mechanism, one draw of its impact sequence: docs/physics.md section 6):

- peak and mean contact force F at E; mean pin pressure F / (d B) (d = 2 R_j, B = bearing length);
- mean p x v, with v = R_j |omega_rod - omega_rocker| the sliding speed of the ideal linkage at the
  same crank angle (the clearance changes the angles by c / L, under 1e-3);
- peak Hertz pressure of the pin in its bore, p0 = sqrt(F' E* / (pi R*)), F' = F_max / B,
  1/R* = 1/R_j - 1/R_b (Johnson, Contact Mechanics, 1985, section 4.3);
- peak |rapier acceleration| and peak |driving torque|.

The CSV also holds revolution 1's peaks, the largest penetration, the wall time of each run and the
plausibility checks that warned (weftsim.checks.design_checks; before = on the ideal mechanism, after = on the
run from revolution 2 on).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import weftsim
from weftsim.mechanism import kinematics as kin
from weftsim.checks.design_checks import after_run, before_run

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("loom", "reference")
SPEEDS_RPM = (300.0, 600.0, 800.0)
CLEARANCES_MM = (0.02, 0.05, 0.1, 0.25)
COLUMNS = ("scene", "speed_rpm", "clearance_mm", "status", "force_peak_kN", "force_mean_kN", "pressure_mean_MPa",
           "pv_mean_MPa_m_s", "hertz_peak_MPa", "acceleration_peak_m_s2", "torque_peak_Nm",
           "force_peak_rev1_kN", "acceleration_peak_rev1_m_s2", "torque_peak_rev1_Nm", "penetration_peak_um",
           "wall_time_s", "warnings")


def hertz_pressure(force, joint) -> float:
    """Peak pressure of a cylinder in a conforming bore (Johnson 1985, 4.3), Pa."""
    inverse_radius = 1.0 / joint.journal_radius - 1.0 / joint.bearing_radius
    return math.sqrt(force / joint.bearing_length * joint.effective_modulus * inverse_radius / math.pi)


def row(scene_name: str, rpm: float, clearance_mm: float, engine: str) -> dict:
    scene = weftsim.load_scene(scene_name, speed_rpm=rpm, clearance_mm=clearance_mm, revolutions=2.0)
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", weftsim.PlausibilityWarning)  # collected below from the checks
        result = weftsim.simulate(scene, engine=engine)
    wall = time.perf_counter() - started
    warned = sorted({f"{c.stage}:{c.name}" for c in before_run(scene) + after_run(result) if c.verdict == "warning"})
    s = result.samples
    angle = s["crank_angle_deg"]
    rev1, rev2 = angle < 360.0, (angle >= 360.0) & (angle < 720.0)
    joint = scene.joint
    area = 2.0 * joint.journal_radius * joint.bearing_length
    omega = scene.drive.speed
    st = kin.linkage_state(np.radians(angle), scene.geometry, scene.inertia.rocker_com)
    sliding = joint.journal_radius * omega * np.abs(st.d_theta_ef - st.d_theta_oe)
    force = s["contact_force_N"]

    def peak(name, mask):
        return float(np.max(np.abs(s[name][mask]))) if mask.any() else float("nan")

    return dict(
        scene=scene_name, speed_rpm=rpm, clearance_mm=clearance_mm, status=result.status,
        force_peak_kN=peak("contact_force_N", rev2) / 1e3, force_mean_kN=float(force[rev2].mean()) / 1e3,
        pressure_mean_MPa=float(force[rev2].mean()) / area / 1e6,
        pv_mean_MPa_m_s=float((force[rev2] / area * sliding[rev2]).mean()) / 1e6,
        hertz_peak_MPa=hertz_pressure(peak("contact_force_N", rev2), joint) / 1e6,
        acceleration_peak_m_s2=peak("rapier_acceleration_m_s2", rev2), torque_peak_Nm=peak("driving_torque_Nm", rev2),
        force_peak_rev1_kN=peak("contact_force_N", rev1) / 1e3,
        acceleration_peak_rev1_m_s2=peak("rapier_acceleration_m_s2", rev1),
        torque_peak_rev1_Nm=peak("driving_torque_Nm", rev1),
        penetration_peak_um=float(np.max(s["penetration_m"])) * 1e6, wall_time_s=wall, warnings=" ".join(warned),
    )


def fmt(value, digits):
    return f"{value:.{digits}f}" if isinstance(value, float) and math.isfinite(value) else str(value)


def markdown(rows: list[dict], speeds=SPEEDS_RPM) -> str:
    """The docs table: loom and reference side by side per speed and clearance."""
    by = {(r["scene"], float(r["speed_rpm"]), float(r["clearance_mm"])): r for r in rows}
    head = ("| rpm | c mm | F peak kN | F mean kN | p mean MPa | p v MPa m/s | Hertz MPa | a peak m/s2 | T peak N m |\n"
            "|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for rpm in speeds:
        for c in CLEARANCES_MM:
            cells = []
            for key, digits in (("force_peak_kN", 1), ("force_mean_kN", 2), ("pressure_mean_MPa", 1),
                                ("pv_mean_MPa_m_s", 2), ("hertz_peak_MPa", 0), ("acceleration_peak_m_s2", 0),
                                ("torque_peak_Nm", 0)):
                pair = [float(by.get((name, rpm, c), {}).get(key, "nan")) for name in SCENES]
                cells.append(" / ".join(fmt(v, digits) for v in pair))
            lines.append(f"| {rpm:g} | {c:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--engine", default="auto")
    parser.add_argument("--out", default=str(ROOT / "docs" / "data" / "loom-loads.csv"))
    parser.add_argument("--scenes", nargs="*", default=list(SCENES))
    parser.add_argument("--table-only", action="store_true", help="print the tables of an existing CSV")
    args = parser.parse_args(argv)
    if args.table_only:
        with Path(args.out).open() as handle:
            rows = list(csv.DictReader(handle))
        print(markdown(rows, (600.0,)), markdown(rows), sep="\n\n")
        return 0
    rows = []
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    for name in args.scenes:
        for rpm in SPEEDS_RPM:
            for c in CLEARANCES_MM:
                r = row(name, rpm, c, args.engine)
                rows.append(r)
                print(", ".join(f"{k}={fmt(v, 3)}" for k, v in r.items()), flush=True)
                with out.open("w", newline="") as handle:
                    writer = csv.DictWriter(handle, fieldnames=COLUMNS)
                    writer.writeheader()
                    writer.writerows({k: fmt(v, 4) for k, v in r.items()} for r in rows)
    print(markdown(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
