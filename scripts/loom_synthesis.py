"""Synthesis of the bundled `loom` mechanism (models/loom.toml; docs/physics.md, "The loom mechanism").

Reproducible: ``PYTHONPATH=. python scripts/loom_synthesis.py`` prints every figure the docs quote and
checks that models/loom.toml holds the values this synthesis chooses.  Ideal joints throughout
(weftsim.mechanism.kinematics); the joint force at E is the Newton-Euler force of the rod and the sector chain
(weftsim.mechanism.pin_loads), which a run at the design clearance reproduces in the mean (tests/test_loom.py).

Steps:
1. Timing and stroke.  The rapier is out of the shed for a third of the cycle, the giver's head passes
   the selvedge at crank angle 60 deg and 300 deg and reaches the middle of the reed at 180 deg
   (two rapiers, transfer in the middle): s(180) - s(60) = W / 2.
2. Spherical crank inclination beta: the smallest peak rapier acceleration for that stroke (20..40 deg).
3. Four-bar O-E-F-G: a parallelogram (L_FG = L_OE, L_EF = L_OG) passes the rocker's motion to the
   sector unchanged; compared with non-parallelogram candidates it gives the lowest peak acceleration
   and transmission angles 90 -/+ beta.
4. Rocker arm L_OE: the joint force at E ~ (rapier-side inertia x acceleration) x stroke / (arc of E);
   the shortest arm whose peak pin pressure at 800 rpm stays below 0.85 of the bushing's permitted
   pressure (the rest is left for the impacts of the clearance).
5. Gear ratios from the stroke: d5 d7 / d6 = stroke / (2 beta), with module-3 teeth.
6. Member masses and inertias from their shapes (:func:`member_inertias`).
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from weftsim.mechanism import kinematics as kin
from weftsim.input.params import Geometry, Inertia
from weftsim.mechanism.pin_loads import ideal_pin_loads
from weftsim.model.ideal import ideal_torque, sector_chain_inertia
from weftsim.input.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]

# --- design targets --------------------------------------------------------------------------------------
REED_WIDTH = 1.90  # m, nominal reed width
SELVEDGE_ANGLE = 60.0  # deg: out of the shed for a third of the cycle (120 deg about beat-up at 0 deg)
NOMINAL_RPM, SPEEDS_RPM = 600.0, (300.0, 600.0, 800.0)
MAX_RAPIER_ACCELERATION = 3000.0  # m/s2, what rapier heads are accelerated to (Previdi et al. 2006)
PIN_DIAMETER, PIN_LENGTH = 30e-3, 30e-3  # m
PERMITTED_PRESSURE = 27.6e6  # Pa, C95400 aluminium bronze, 4000 psi
PERMITTED_PV = 4.38e6  # Pa m/s, C95400, 125000 psi ft/min
PRESSURE_MARGIN = 0.85  # ideal peak at 800 rpm / permitted pressure: the rest for impacts
MODULE = 3e-3  # m, gear module of sector and pinion
PINION_TEETH = 20
RAPIER_WHEEL_RADIUS = 0.150  # m, pitch radius of the rapier wheel (300 mm wheel)
RAPIER_MASS = 0.35  # kg, band and head
WHEEL_INERTIA = 0.012  # kg m2, pinion and rapier wheel
STEEL, BRONZE, ALUMINIUM = 7850.0, 7450.0, 2700.0  # kg/m3

GRID = np.radians(np.arange(0.0, 360.0, 0.1))


def shape(theta_deg, geometry: Geometry) -> float:
    """Rapier displacement at crank angle theta over the stroke s(180)."""
    st = kin.linkage_state(np.radians([theta_deg, 180.0]), geometry)
    return float(st.rapier_displacement[0] / st.rapier_displacement[1])


def stroke_for_width(geometry: Geometry) -> float:
    """Stroke S with S (1 - s(60)/S) = W / 2 (step 1)."""
    return 0.5 * REED_WIDTH / (1.0 - shape(SELVEDGE_ANGLE, geometry))


def parallelogram(beta_deg: float, l_oe: float, l_og: float, ratio: float = 1.0) -> Geometry:
    """Parallelogram four-bar about theta_OE0 = 90 deg, rapier ratio d5 d7 / d6 = ``ratio`` m/rad."""
    return Geometry(crank_inclination=math.radians(beta_deg), rocker_arm_angle=math.radians(90.0),
                    l_oe=l_oe, l_ef=l_og, l_fg=l_oe, l_og=l_og, fourbar_branch=1,
                    sector_pitch_radius=ratio, pinion_pitch_radius=1.0, rapier_gear_pitch_radius=1.0)


def with_stroke(geometry: Geometry) -> Geometry:
    """``geometry`` with its rapier ratio scaled so the stroke meets step 1."""
    s180 = kin.linkage_state(np.radians([180.0]), geometry).rapier_displacement[0]
    scale = stroke_for_width(geometry) / s180
    return replace(geometry, sector_pitch_radius=geometry.sector_pitch_radius * scale)


# --- member shapes (step 6) -------------------------------------------------------------------------------
def tube(outer, wall, length, density):
    """Mass of a tube, kg."""
    return density * math.pi * (outer**2 - (outer - 2 * wall) ** 2) / 4.0 * length


def bearing_eye():
    """Steel eye (56 mm outside, 38 mm bore, 30 mm long) holding a bronze bushing 38/30 x 30 mm, kg."""
    return tube(0.056, 0.009, PIN_LENGTH, STEEL) + tube(0.038, 0.004, PIN_LENGTH, BRONZE)


def member_inertias(geometry: Geometry) -> dict:
    """Masses and inertias of members 3, 4 and 5 from their shapes (step 6 of the module docstring)."""
    eye = bearing_eye()
    # rocker 3: steel bar 40 x 20 mm along OE, an eye at E, a hub (60 mm x 40 mm) on axis D
    bar = STEEL * 0.040 * 0.020 * geometry.l_oe
    hub = STEEL * math.pi * 0.030**2 * 0.040
    m3 = bar + eye + hub
    com3 = (bar * geometry.l_oe / 2 + eye * geometry.l_oe) / m3
    j3 = bar * geometry.l_oe**2 / 3 + eye * geometry.l_oe**2 + hub * 0.030**2 / 2
    # rod 4: steel tube 30 x 3 mm between the eyes at E and F
    pipe = tube(0.030, 0.003, geometry.l_ef, STEEL)
    m4 = pipe + 2 * eye
    j4 = pipe * geometry.l_ef**2 / 12 + 2 * eye * (geometry.l_ef / 2) ** 2
    # sector 5: aluminium plate 20 mm thick, radius (pitch radius + one module), over the swing + 20 deg
    swing = 2 * geometry.crank_inclination + math.radians(20.0)
    radius = geometry.sector_pitch_radius + MODULE
    m5 = ALUMINIUM * 0.020 * swing / 2 * radius**2
    j5 = m5 * radius**2 / 2
    return dict(eye=eye, rocker_mass=m3, rocker_com=com3, rocker_inertia=j3, rod_mass=m4, rod_inertia=j4,
                sector_mass=m5, sector_inertia=j5)


def loads(geometry: Geometry, inertia: Inertia, rpm: float) -> dict:
    """Ideal-joint figures at ``rpm``: force at E (weftsim.mechanism.pin_loads, Newton-Euler of the chain behind E),
    pin pressure, p x v, rapier acceleration, driving torque."""
    omega = rpm * math.pi / 30.0
    base = load_scene("reference")
    scene = replace(base, geometry=geometry, inertia=inertia, drive=replace(base.drive, speed=omega),
                    joint=replace(base.joint, journal_radius=PIN_DIAMETER / 2, bearing_length=PIN_LENGTH))
    pin = ideal_pin_loads(scene, "e")
    pressure = pin.force / (PIN_DIAMETER * PIN_LENGTH)
    st = kin.linkage_state(pin.theta, geometry, inertia.rocker_com)
    torque = ideal_torque(pin.theta, scene)
    return dict(force_peak=pin.force.max(), force_mean=pin.force.mean(), pressure_peak=pressure.max(),
                pressure_mean=pressure.mean(), pv_mean=(pressure * pin.sliding_speed).mean(),
                sliding_peak=pin.sliding_speed.max(), acceleration=np.abs(omega**2 * st.dd_rapier_displacement).max(),
                torque=np.abs(torque).max(), reflected_mass=pin.reflected_mass.max())


def main() -> int:
    print(f"step 1: reed width {REED_WIDTH} m, selvedge at {SELVEDGE_ANGLE:g} deg and "
          f"{360 - SELVEDGE_ANGLE:g} deg, middle at 180 deg")
    omega = NOMINAL_RPM * math.pi / 30.0
    print("step 2: crank inclination beta (parallelogram four-bar)")
    best = None
    for beta in (20.0, 25.0, 30.0, 35.0, 40.0):
        g = with_stroke(parallelogram(beta, 0.24, 0.336))
        acc = np.abs(omega**2 * kin.linkage_state(GRID, g).dd_rapier_displacement).max()
        print(f"  beta {beta:4.1f} deg: stroke {stroke_for_width(g):.4f} m, s(60)/S {shape(60, g):.4f}, "
              f"peak acceleration at {NOMINAL_RPM:g} rpm {acc:7.1f} m/s2")
        if best is None or acc < best[1]:
            best = (beta, acc)
    beta = best[0]
    print(f"  -> beta = {beta:g} deg")

    print("step 3: four-bar shape (L_OE = 0.24 m, L_OG = 0.336 m, theta_OE0 = 90 deg)")
    for label, l_fg, l_ef in (("parallelogram", 0.24, 0.336), ("L_FG = 0.8 L_OE", 0.192, 0.336),
                              ("L_FG = 1.2 L_OE", 0.288, 0.336), ("L_EF = 1.2 L_OG", 0.24, 0.403)):
        g = with_stroke(replace(parallelogram(beta, 0.24, 0.336), l_fg=l_fg, l_ef=l_ef))
        st = kin.linkage_state(GRID, g)
        acc = omega**2 * st.dd_rapier_displacement
        mu = np.degrees(st.transmission_angle)
        print(f"  {label:16s}: stroke {stroke_for_width(g):.4f} m, acceleration {acc.min():8.1f} .. "
              f"{acc.max():7.1f} m/s2, transmission angle {mu.min():6.2f} .. {mu.max():6.2f} deg")

    print("step 4: rocker arm L_OE (parallelogram, L_OG = 1.4 L_OE), ideal joints at 800 rpm")
    chosen = None
    for l_oe in (0.16, 0.20, 0.24, 0.28):
        g = with_stroke(parallelogram(beta, l_oe, 1.4 * l_oe))
        g = gears(g)
        inert = inertia_for(g)
        top = loads(g, inert, max(SPEEDS_RPM))
        ok = top["pressure_peak"] <= PRESSURE_MARGIN * PERMITTED_PRESSURE
        print(f"  L_OE {l_oe:.2f} m: peak force at E {top['force_peak'] / 1e3:6.2f} kN, pin pressure "
              f"{top['pressure_peak'] / 1e6:5.1f} MPa (limit {PRESSURE_MARGIN:g} x "
              f"{PERMITTED_PRESSURE / 1e6:g} = {PRESSURE_MARGIN * PERMITTED_PRESSURE / 1e6:.1f}){' ok' if ok else ''}")
        if ok and chosen is None:
            chosen = l_oe
    geometry = gears(with_stroke(parallelogram(beta, chosen, 1.4 * chosen)))
    inertia = inertia_for(geometry)
    print(f"  -> L_OE = L_FG = {chosen:g} m, L_EF = L_OG = {1.4 * chosen:.3f} m")

    print("step 5: gears")
    ideal_ratio = with_stroke(parallelogram(beta, chosen, 1.4 * chosen)).rapier_ratio
    print(f"  rapier ratio for the stroke {ideal_ratio:.4f} m/rad; pinion {PINION_TEETH} teeth, module "
          f"{MODULE * 1e3:g} mm: d6 = {geometry.pinion_pitch_radius * 1e3:g} mm; sector "
          f"{round(2 * geometry.sector_pitch_radius / MODULE)} teeth: d5 = {geometry.sector_pitch_radius * 1e3:g} mm;"
          f" d7 = {geometry.rapier_gear_pitch_radius * 1e3:g} mm; ratio {geometry.rapier_ratio:.4f} m/rad")
    st = kin.linkage_state(GRID, geometry)
    stroke = kin.linkage_state(np.radians([180.0]), geometry).rapier_displacement[0]
    s60 = kin.linkage_state(np.radians([SELVEDGE_ANGLE]), geometry).rapier_displacement[0]
    mu = np.degrees(st.transmission_angle)
    print(f"  stroke {stroke:.4f} m, selvedge at s = {s60:.4f} m, s(180) - s(60) = {stroke - s60:.4f} m "
          f"(W/2 = {REED_WIDTH / 2:g}); transmission angle at F {mu.min():.2f} .. {mu.max():.2f} deg; "
          f"spherical 4R (angle of b and axis D) {90 - beta:g} .. {90 + beta:g} deg")

    print("step 6: members")
    shapes = member_inertias(geometry)
    for key, value in shapes.items():
        print(f"  {key:16s} {value:.4g}")
    j_fg = sector_chain_inertia(replace(load_scene("reference"), geometry=geometry, inertia=inertia))
    print(f"  sector chain inertia J_FG {j_fg:.4f} kg m2; seen at F: {j_fg / geometry.l_fg**2:.1f} kg")

    print("loads, ideal joints (pin 30 x 30 mm)")
    for rpm in SPEEDS_RPM:
        r = loads(geometry, inertia, rpm)
        print(f"  {rpm:4.0f} rpm: F_E peak {r['force_peak'] / 1e3:6.2f} kN, mean {r['force_mean'] / 1e3:6.2f} kN, "
              f"p peak {r['pressure_peak'] / 1e6:5.2f} MPa, mean {r['pressure_mean'] / 1e6:5.2f} MPa, "
              f"mean p x v {r['pv_mean'] / 1e6:5.2f} MPa m/s, peak sliding {r['sliding_peak']:.3f} m/s, "
              f"peak acceleration {r['acceleration']:7.1f} m/s2, peak torque {r['torque']:7.1f} N m, "
              f"reflected mass at E up to {r['reflected_mass']:.1f} kg")
        over = [what for what, value, limit in (("pin pressure", r["pressure_peak"], PERMITTED_PRESSURE),
                                                ("p x v", r["pv_mean"], PERMITTED_PV),
                                                ("rapier acceleration", r["acceleration"], MAX_RAPIER_ACCELERATION))
                if value > limit]
        print(f"           above its limit: {', '.join(over) if over else 'nothing'}")
    return check_scene(geometry, inertia)


def gears(geometry: Geometry) -> Geometry:
    """Module-3 pinion and sector and the rapier wheel: the sector's teeth rounded up, so the head reaches W/2."""
    d6 = MODULE * PINION_TEETH / 2
    teeth = math.ceil(2 * geometry.rapier_ratio * d6 / RAPIER_WHEEL_RADIUS / MODULE)
    return replace(geometry, sector_pitch_radius=MODULE * teeth / 2, pinion_pitch_radius=d6,
                   rapier_gear_pitch_radius=RAPIER_WHEEL_RADIUS)


def inertia_for(geometry: Geometry) -> Inertia:
    """Inertia of the loom: members 3-5 from their shapes, wheel and rapier from the targets."""
    s = member_inertias(geometry)
    return Inertia(rocker_mass=round(s["rocker_mass"], 2), rocker_com=round(s["rocker_com"], 3),
                   rocker_inertia=round(s["rocker_inertia"], 4), rod_mass=round(s["rod_mass"], 2),
                   rod_inertia=round(s["rod_inertia"], 4), sector_inertia=round(s["sector_inertia"], 4),
                   pinion_gear_inertia=WHEEL_INERTIA, rapier_mass=RAPIER_MASS)


def check_scene(geometry: Geometry, inertia: Inertia) -> int:
    """0 if models/loom.toml holds this synthesis's geometry and inertias (to their printed digits)."""
    path = ROOT / "models" / "loom.toml"
    if not path.exists():
        print(f"{path} not found")
        return 1
    scene = load_scene(path)
    skipped = {"crank_inertia", "coupler_mass", "coupler_inertia", "gravity"}  # the reference's, not synthesised
    bad = []
    for have_in, want_in in ((scene.geometry, geometry), (scene.inertia, inertia)):
        for name, want in vars(want_in).items():
            have = getattr(have_in, name)
            if name not in skipped and not np.isclose(have, want, rtol=1e-9, atol=1e-12):
                bad.append(f"{name}: scene {have!r}, synthesis {want!r}")
    print("models/loom.toml", "matches the synthesis" if not bad else "DIFFERS: " + "; ".join(bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
