"""The schema of a scene file: every key, its unit, its range and where it goes in :class:`weftsim.input.params.Scene`.

:data:`SCHEMA` is the single list of keys (the README's and the site's scene reference are written from it);
:mod:`weftsim.input.scene` reads files against it and :mod:`weftsim.input.joint_keys` (which keys joint F takes from
joint E, which describe an ideal joint) reads it too.  Split off :mod:`weftsim.input.scene` so that the joint keys
need no scene reader, and the reader imports the joint keys without an import circle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from weftsim.input import params

INTEGRATORS = ("auto", "DOP853", "RK45", "RK23", "Radau", "LSODA", "BDF", "numba_DOP853", "numba_RK45", "numba_RODAS4",
               "numba_DOP853_RODAS4")
EXUDYN_MODELS = ("auto", "rigid_body", "kinematic_tree")
EXPLICIT_METHODS = ("DOPRI5", "ODE23")
TREE_SOLVERS = ("auto", "explicit", "implicit")
STEP_CONTROLS = ("adaptive", "fixed")
CALLBACK_ROUTES = ("auto", "python", "symbolic", "numba")
BRANCHES = {"+": 1, "-": -1}
IMPACT_VELOCITY_RULES = params.IMPACT_VELOCITY_RULES


@dataclass(frozen=True)
class Key:
    """One scene-file key: where it goes, its unit conversion and its allowed range."""

    path: str  # dotted TOML key, e.g. "joint_e.clearance_mm"
    target: str  # "<scene attribute>.<field>" or deeper, e.g. "joint.clearance"
    kind: str  # "float", "int", "bool", "str", "floats2", "floats3"
    scale: float = 1.0  # SI value = file value * scale
    low: float | None = None
    high: float | None = None
    low_open: bool = True  # low excluded
    high_open: bool = False  # high excluded
    choices: tuple = ()
    doc: str = ""

    def allowed(self) -> str:
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        parts = []
        if self.low is not None:
            parts.append(f"{'>' if self.low_open else '>='} {self.low:g}")
        if self.high is not None:
            parts.append(f"{'<' if self.high_open else '<='} {self.high:g}")
        return " and ".join(parts) or "any finite value"


MM, DEG, GPA, MPA, RPM = 1e-3, math.pi / 180.0, 1e9, 1e6, 2.0 * math.pi / 60.0
# Upper bounds of the machine's keys: far beyond any loom (a linkage of a few hundred mm, members of a few
# kg, a 20 mm pin, steel at 210 GPa), so that only a typo or a unit slip meets them, and a value past them
# is refused naming its key instead of failing later with a message about something else.
LENGTH_MM = 1e4  # 10 m
PIN_MM = 1e3
MASS_KG = 1e3
INERTIA_KG_M2 = 1e3
SPEED_M_S = 10.0  # friction ramp and impact-velocity floor: the journal's sliding speed is ~1 m/s
MODULUS_GPA = 1e4  # diamond: 1.2e3 GPa
STRESS_MPA = 1e5
VISCOSITY_MPA_S = 1e5  # a gear oil well below freezing is ~1e4 mPa s
VISCOSITY_MM2_S = 1e5  # the same as a kinematic viscosity (oils weigh ~0.9 kg/l); ISO VG 3200 is the top grade
ROUGHNESS_UM = 100  # combined RMS roughness: ground 0.1-0.8 um, turned 1-6, sand cast ~25 (Ra, ISO 1302)
# Tolerances of the solvers: below 1e-14 (50 eps) a step's error estimate is round-off and the step control
# chases it to a collapse (solver.reference.atol = 1e-20 collapsed the first step to 3e-17 s).
TOLERANCE_FLOOR = 1e-14
# The reference engine's absolute tolerance, in the state's units (rad, m and their rates), reaches one decade
# lower: the converged runs of weftsim.bench take atol = rtol x 1e-3 = 1e-15 at rtol 1e-12.  Measured on the
# reference, oiled reference and loom scenes: at atol 1e-15 every method (numba_DOP853, _RK45, _RODAS4,
# _DOP853_RODAS4, scipy DOP853, Radau) runs at rtol 1e-5 and 1e-12; at 1e-16 and the default rtol 1e-5 each
# fails its first step (the state's rates, at the linkage's dead centre, and its integrated energies start at
# 0, so their tolerance is atol alone and scipy's initial-step rule gives 2.9e-13 s, below limits.min_step_s =
# 1e-12 s).  The rule's step scales with atol / rtol: pairs below ~1e-10 fail so too (atol 1e-13 at rtol 1e-2).
ATOL_FLOOR = 1e-15


def WEAR_KEYS(table: str, joint: str) -> tuple[Key, ...]:  # noqa: N802 - a constant-like key factory
    """The ``[<table>.wear]`` keys of a clearance joint (weftsim wear; docs/wear.md), all optional."""
    return (
        # k spans 1e-2 (severe, dry) to below 1e-6 (Archard 1953; Rabinowicz 1995); hardness from soft
        # polymer bushings (~10 MPa) to ceramics and diamond (~1e5 MPa).  Beyond these the wear per update
        # dwarfs the clearance and the cycle extrapolation cannot follow it (issue 24).
        Key(f"{table}.wear.regime", f"{joint}.wear.regime", "str", choices=params.WEAR_REGIMES,
            doc="regime of the solid contact: \"boundary\" (default: grease or oil on the surfaces, no film) or "
                "\"dry\" (unlubricated); an oil film's asperities take mixed_wear_coefficient"),
        Key(f"{table}.wear.dry_wear_coefficient", f"{joint}.wear.dry_wear_coefficient", "float", 1, 0, 1e-2, True,
            False, doc="Archard's k of unlubricated contact (default 5e-3, steel on steel; docs/wear.md section 5)"),
        Key(f"{table}.wear.boundary_wear_coefficient", f"{joint}.wear.boundary_wear_coefficient", "float", 1, 0,
            1e-2, True, False, doc="Archard's k of boundary-lubricated contact (default 1e-7)"),
        Key(f"{table}.wear.mixed_wear_coefficient", f"{joint}.wear.mixed_wear_coefficient", "float", 1, 0, 1e-2,
            True, False, doc="Archard's k of the asperity load of an oil-lubricated joint (default 1e-7)"),
        # Running-in (weftsim.wear.extrapolate.run_in_roughness): the roughness it ends at becomes the film's
        # roughness, so it is bounded as roughness_um (> 0, <= 100 um); the worn depth it takes is a few
        # roughnesses (Queener et al. 1965; default 1 um), so 1000 um (a fifth of the largest clearance) is a
        # unit slip.
        Key(f"{table}.wear.run_in_roughness_um", f"{joint}.wear.run_in_roughness", "float", 1e-6, 0, ROUGHNESS_UM,
            doc="running-in: the combined RMS roughness an oiled joint's surfaces wear down to (default: none)"),
        Key(f"{table}.wear.run_in_depth_um", f"{joint}.wear.run_in_depth", "float", 1e-6, 0, 1000,
            doc="running-in: the worn depth over which the roughness falls by 1/e towards it (default 1 um)"),
        Key(f"{table}.wear.wear_coefficient", f"{joint}.wear.wear_coefficient", "float", 1, 0, 1e-2, True, False,
            doc="one Archard k for every load of the joint, overriding the regime keys (optional)"),
        Key(f"{table}.wear.bearing_hardness_mpa", f"{joint}.wear.bearing_hardness", "float", MPA, 1, 1e5, False,
            doc="hardness H of the bearing surface (default 2000 MPa, hardened steel)"),
        Key(f"{table}.wear.journal_hardness_mpa", f"{joint}.wear.journal_hardness", "float", MPA, 1, 1e5, False,
            doc="hardness H of the journal surface (default 2000 MPa)"),
        Key(f"{table}.wear.max_clearance_change", f"{joint}.wear.max_clearance_change", "float", 1, 0, 0.5, True,
            False, doc="update criterion: largest growth of the effective clearance per update, as a fraction"),
        Key(f"{table}.wear.revolutions_per_update", f"{joint}.wear.revolutions_per_update", "int", 1, 0, 1000,
            doc="steady crank revolutions simulated per geometry update"),
        Key(f"{table}.wear.settle_revolutions", f"{joint}.wear.settle_revolutions", "int", 1, 0, 100, False,
            doc="revolutions simulated first and not counted (start from the centred journal)"),
        # At least 180 (2 deg cells): on the reference loom, profiles of 8, 16, 36, 72 and 120 points failed
        # the contact-history check within 5 h (damping above the bound, the contact's rate of clearance
        # change dc/dt jumping between coarse knots); 180 and 240 ran 25 h, as the default 360 does (issue 24).
        Key(f"{table}.wear.profile_points", f"{joint}.wear.profile_points", "int", 1, 180, 100000, False,
            doc="points of the tabulated wear profiles over 360 deg (>= 180: coarser ones break the worn contact)"),
    )


def LUBRICATION_KEYS(table: str, joint: str) -> tuple[Key, ...]:  # noqa: N802 - a constant-like key factory
    """The ``[<table>.lubrication]`` keys of a clearance joint (docs/lubricated-joint.md).  The table is optional
    (absent: the dry joint); given, it must name ``viscosity_mpa_s``, the other keys default."""
    at = f"{table}.lubrication."
    to = f"{joint}.lubrication."
    return (
        Key(at + "viscosity_mpa_s", to + "viscosity", "float", 1e-3, 0, VISCOSITY_MPA_S, False,
            doc="dynamic viscosity of the oil at operating temperature (ISO VG 220 at 60 C: ~80 mPa s); 0 = no film"),
        Key(at + "model", to + "model", "str", choices=params.FILM_MODELS,
            doc="film model: finite (finite-length bearing, default), short (Ocvirk), long (Sommerfeld) or "
                "short_half (Flores et al.'s short bearing)"),
        Key(at + "roughness_um", to + "roughness", "float", 1e-6, 0, ROUGHNESS_UM,
            doc="combined RMS roughness of journal and bearing (default 0.4 um, two ground surfaces)"),
        Key(at + "asperity_density_radius_roughness", to + "asperity_density_radius_roughness", "float", 1, 0, 1,
            False, doc="Greenwood-Tripp eta beta sigma (default 0.04); 0 = no asperity contact"),
        Key(at + "roughness_radius_ratio", to + "roughness_radius_ratio", "float", 1, 0, 1,
            doc="Greenwood-Tripp sigma / beta, RMS roughness over asperity summit radius (default 1e-3)"),
        Key(at + "boundary_friction_coefficient", to + "boundary_friction_coefficient", "float", 1, 0, 2, False,
            doc="friction coefficient of the solids' contact in oil, asperities and dry law (default 0.1)"),
        Key(at + "film_floor_ratio", to + "film_floor_ratio", "float", 1, 0.25, 4, False,
            doc="the film force is evaluated down to this many RMS roughnesses and continued below it with its slope "
                "there, to sigma / 4 (default 1; a numerical knob: docs/lubricated-joint.md)"),
        Key(at + "elastic_film", to + "elastic_film", "bool",
            doc="weftsim bearing: the steady point with the surfaces' elastic deformation (EHL, plane strain, moduli "
                "of journal_material and bearing_material; default false; transient runs refuse it)"),
        Key(at + "summit_height_um", to + "summit_height", "float", 1e-6, 0, 4 * ROUGHNESS_UM, False,
            doc="mean height of the asperity summits above the mean planes (both surfaces): Greenwood-Tripp at "
                "h - delta (elastic film only; default 0)"),
        Key(at + "pressure_viscosity_per_gpa", to + "pressure_viscosity", "float", 1e-9, 0, 100, False,
            doc="Barus' pressure-viscosity coefficient alpha, 1/GPa (mineral oils 10-30; elastic film only; "
                "default 0: isoviscous)"),
        Key(at + "surface_roughness_um", to + "surface_roughness", "floats2", 1e-6, 0, ROUGHNESS_UM,
            doc="[journal, bearing] RMS roughness of each surface for the elastic film's average flow (its H on "
                "their composite, the shear flow of unlike surfaces; roughness_um stays the asperities'; elastic "
                "film only; default unset: alike, of roughness_um)"),
        # Patir and Cheng fitted gamma = 1/9 to 9; a bound of 100 refuses only a typo (beyond 9 the fit's last column
        # is read, weftsim.physics.flow_factors).
        Key(at + "peklenik_numbers", to + "peklenik_numbers", "floats2", 1, 0, 100,
            doc="[journal, bearing] Peklenik numbers (correlation length along the motion over across it; > 1 "
                "ridges along it) for Patir and Cheng's anisotropic flow factors (elastic film only; default "
                "unset: isotropic)"),
        Key(at + "asperity_modulus_gpa", to + "asperity_modulus", "float", GPA, 0, 1e4, False,
            doc="E* of the asperity contact where a source gives it apart from the materials (default 0: the "
                "joint's effective modulus)"),
        # The oil and the heat balance (weftsim.physics.oil, weftsim.joint.heat): instead of viscosity_mpa_s.
        Key(at + "oil", to + "oil", "str",
            doc="an ISO 3448 grade (\"ISO VG 220\"): the viscosity follows from the film temperature of the "
                "bearing's heat balance (instead of viscosity_mpa_s)"),
        # A custom oil's bounds: ISO 3448's grades run from VG 2 to VG 3200 (nu40 in mm^2/s), so 1e5 mm^2/s (as
        # VISCOSITY_MPA_S) is only a typo.  Liquid lubricants weigh 800 (light mineral oil) to 1950 kg/m^3
        # (perfluoropolyether) and hold 1000 (PFPE) to 2500 J/(kg K) (glycols), water 4186: the bounds below
        # pass them with room and refuse g/cm^3 (0.88) or kJ/(kg K) (2.0) given for the SI unit.
        Key(at + "oil.nu40_mm2_s", to + "oil_nu40", "float", 1e-6, 0, VISCOSITY_MM2_S, False,
            doc="a custom oil instead of a grade: kinematic viscosity at 40 C"),
        Key(at + "oil.nu100_mm2_s", to + "oil_nu100", "float", 1e-6, 0, VISCOSITY_MM2_S, False,
            doc="a custom oil: kinematic viscosity at 100 C (ASTM D341 through the two)"),
        Key(at + "oil.density_kg_m3", to + "oil_density", "float", 1, 300, 3000, False,
            doc="density of the oil at 15 C (default 880, a mineral oil)"),
        Key(at + "oil.heat_capacity_j_kg_k", to + "oil_heat_capacity", "float", 1, 500, 10000, False,
            doc="specific heat of the oil (default 2000)"),
        Key(at + "ambient_temperature_c", to + "ambient_temperature", "float", 1, -40, 150, False, False,
            doc="temperature of the air around the joint and of the oil fed to it (default 25 C)"),
        # k A of the pin's eye in still air is ~0.05 W/K (weftsim.joint.heat.housing_estimate); a water-cooled
        # housing of 0.1 m^2 at 5000 W/(m^2 K) is 500 W/K: 1000 W/K is past any pin joint of a loom.
        Key(at + "housing_heat_transfer_w_k", to + "housing_heat_transfer", "float", 1, 0, 1000, False,
            doc="heat flow through the housing to the air per kelvin, k A (default: estimated for the pin's eye)"),
        Key(at + "oil_supply", to + "oil_supply", "str", choices=params.OIL_SUPPLIES,
            doc="fed (oil at ambient temperature floods the film and carries heat off, default) or sump "
                "(self-contained: heat through the housing alone)"),
    )


# [rapier_tape] (docs/rapier-tape.md): optional as a whole (absent: the rigid rapier of mass m8); given, every key
# defaults (params.RapierTape states the defaults' basis).  Ranges: what the axial bar model describes.
TAPE_MODELS = params.TAPE_MODELS
RAPIER_TAPE_KEYS: tuple[Key, ...] = (
    Key("rapier_tape.length_mm", "rapier_tape.length", "float", MM, 0, 1e5,
        doc="whole tape from the head to its tail behind the wheel (>= free_length_mm + the stroke); default 1900"),
    Key("rapier_tape.width_mm", "rapier_tape.width", "float", MM, 0, 1000, doc="tape width (default 30, assumed)"),
    Key("rapier_tape.thickness_mm", "rapier_tape.thickness", "float", MM, 0, 100,
        doc="tape thickness (default 2.5, assumed)"),
    Key("rapier_tape.axial_modulus_gpa", "rapier_tape.axial_modulus", "float", GPA, 0, 1000,
        doc="axial Young's modulus (default 100: carbon/epoxy laminate, 2/3 of the plies at 0 deg)"),
    Key("rapier_tape.density_kg_m3", "rapier_tape.density", "float", 1, 0, 20000,
        doc="density (default 1580: carbon/epoxy)"),
    Key("rapier_tape.damping_time_us", "rapier_tape.damping_time", "float", 1e-6, 0, 1e4, False,
        doc="Kelvin-Voigt structural damping, stress = E (strain + tau strain rate) (default 1 us); 0 = none"),
    Key("rapier_tape.head_mass_kg", "rapier_tape.head_mass", "float", 1, 0, 100, doc="rapier head (default 0.125)"),
    Key("rapier_tape.free_length_mm", "rapier_tape.free_length", "float", MM, 0, 1e5,
        doc="the wheel's engagement: free tape from where it leaves the wheel to the head, rapier outermost "
            "(default 250)"),
    Key("rapier_tape.guide_friction_coefficient", "rapier_tape.guide_friction_coefficient", "float", 1, 0, 2,
        False, doc="Coulomb friction of head and free tape on the guide rail under their weight (default 0: off)"),
    Key("rapier_tape.model", "rapier_tape.model", "str", choices=TAPE_MODELS,
        doc="auto: the rigid rapier when the tape's first mode over the stroke is far above the drive's "
            "harmonics, else the flexible tape; flexible; rigid (tape and head as one mass)"),
    Key("rapier_tape.modes", "rapier_tape.modes", "int", 1, 2, 8, False, False,
        doc="Ritz functions of the tape's axial displacement (default 4)"),
)


# [exchange] (docs/rapier-tape.md section 7): optional as a whole (absent: no taker head, nothing computed); given,
# every key defaults (params.Exchange names its assumptions).  The taker's clearance is bounded as joint E's.
EXCHANGE_KEYS: tuple[Key, ...] = (
    Key("exchange.enabled", "exchange.enabled", "bool",
        doc="compute the exchange with the taker head (default true once the table is given)"),
    Key("exchange.taker_clearance_mm", "exchange.taker_clearance", "float", MM, 0, PIN_MM, False,
        doc="the taker's radial clearance at E, 0 = ideal (default: the giver's, joint_e.clearance_mm)"),
    Key("exchange.overlap_mm", "exchange.overlap", "float", MM, 0, LENGTH_MM,
        doc="how far the ideal heads pass each other at the dead centre (default 50, assumed)"),
    Key("exchange.window_deg", "exchange.window", "float", DEG, 0, 360,
        doc="full width of the transfer window in crank angle about the dead centre (default: where the "
            "ideal heads overlap)"),
)

SCHEMA: tuple[Key, ...] = (
    Key("mechanism.crank_inclination_deg", "geometry.crank_inclination", "float", DEG, 0, 90, True, True,
        doc="beta, arc A-B of the spherical 4R"),
    Key("mechanism.rocker_arm_angle_deg", "geometry.rocker_arm_angle", "float", DEG, -360, 360, False, False,
        doc="theta_OE0, angle of OE from +y towards +z at phi = 0"),
    Key("mechanism.l_oe_mm", "geometry.l_oe", "float", MM, 0, LENGTH_MM, doc="rocker arm OE"),
    Key("mechanism.l_ef_mm", "geometry.l_ef", "float", MM, 0, LENGTH_MM, doc="connecting rod EF"),
    Key("mechanism.l_fg_mm", "geometry.l_fg", "float", MM, 0, LENGTH_MM, doc="sector arm FG"),
    Key("mechanism.l_og_mm", "geometry.l_og", "float", MM, 0, LENGTH_MM, doc="frame O-G"),
    Key("mechanism.fourbar_branch", "geometry.fourbar_branch", "str", choices=tuple(BRANCHES),
        doc="assembly branch of the four-bar (docs/physics.md section 1: \"+\")"),
    Key("mechanism.sector_pitch_radius_mm", "geometry.sector_pitch_radius", "float", MM, 0, LENGTH_MM, doc="d5"),
    Key("mechanism.pinion_pitch_radius_mm", "geometry.pinion_pitch_radius", "float", MM, 0, LENGTH_MM, doc="d6"),
    Key("mechanism.rapier_gear_pitch_radius_mm", "geometry.rapier_gear_pitch_radius", "float", MM, 0, LENGTH_MM, doc="d7"),
    Key("inertia.crank_inertia_kg_m2", "inertia.crank_inertia", "float", 1, 0, INERTIA_KG_M2, doc="J1 about A"),
    Key("inertia.coupler_mass_kg", "inertia.coupler_mass", "float", 1, 0, MASS_KG, doc="m2 (centre of mass at O)"),
    Key("inertia.coupler_inertia_kg_m2", "inertia.coupler_inertia", "floats3", 1, 0, INERTIA_KG_M2,
        doc="principal inertia of the coupler about O in [b, c, b x c]"),
    Key("inertia.rocker_mass_kg", "inertia.rocker_mass", "float", 1, 0, MASS_KG, doc="m3"),
    Key("inertia.rocker_com_mm", "inertia.rocker_com", "float", MM, -LENGTH_MM, LENGTH_MM, False, doc="rocker centre of mass on OE from O"),
    Key("inertia.rocker_inertia_kg_m2", "inertia.rocker_inertia", "float", 1, 0, INERTIA_KG_M2, doc="J3 about D"),
    Key("inertia.rod_mass_kg", "inertia.rod_mass", "float", 1, 0, MASS_KG, doc="m4 (centre of mass mid EF)"),
    Key("inertia.rod_inertia_kg_m2", "inertia.rod_inertia", "float", 1, 0, INERTIA_KG_M2, doc="J4 about its centre of mass"),
    Key("inertia.sector_inertia_kg_m2", "inertia.sector_inertia", "float", 1, 0, INERTIA_KG_M2, doc="J5 about G"),
    Key("inertia.pinion_gear_inertia_kg_m2", "inertia.pinion_gear_inertia", "float", 1, 0, INERTIA_KG_M2, doc="J67"),
    Key("inertia.rapier_mass_kg", "inertia.rapier_mass", "float", 1, 0, MASS_KG, doc="m8"),
    Key("inertia.gravity_m_s2", "inertia.gravity", "float", 1, 0, 100, doc="g along -z"),
    Key("joint_e.clearance_mm", "joint.clearance", "float", MM, 0, 5, False, doc="radial clearance c; 0 = ideal joint"),
    Key("joint_e.journal_radius_mm", "joint.journal_radius", "float", MM, 0, PIN_MM, doc="R_j"),
    Key("joint_e.bearing_length_mm", "joint.bearing_length", "float", MM, 0, PIN_MM, doc="L_b"),
    Key("joint_e.bushing_wall_mm", "joint.bushing_wall", "float", MM, 0, PIN_MM,
        doc="optional; t, the bushing's radial wall to its housing (the cylindrical law needs it)"),
    Key("joint_e.law", "joint.law", "str", doc="contact force law (see weftsim.joint.contact.LAWS)"),
    Key("joint_e.restitution", "joint.restitution", "float", 1, 0, 1, True, False, doc="coefficient of restitution ce"),
    Key("joint_e.friction_coefficient", "joint.friction_coefficient", "float", 1, 0, 2, False,
        doc="mu of the modified Coulomb law; 0 = off"),
    Key("joint_e.friction_velocities_m_s", "joint.friction_velocities", "floats2", 1, 0, SPEED_M_S,
        doc="[v0, v1] of the friction ramp, v0 < v1"),
    Key("joint_e.min_impact_velocity_m_s", "joint.min_impact_velocity", "float", 1, 0, SPEED_M_S,
        doc="floor on the held impact velocity"),
    Key("joint_e.impact_velocity_rule", "joint.impact_velocity_rule", "str", choices=IMPACT_VELOCITY_RULES,
        doc="held impact velocity: largest approach rate since onset, or the onset value alone"),
    Key("joint_e.journal_material.youngs_modulus_gpa", "joint.journal_material.youngs_modulus", "float", GPA, 0, MODULUS_GPA),
    Key("joint_e.journal_material.poisson_ratio", "joint.journal_material.poisson_ratio", "float", 1, 0, 0.5,
        False, True),
    Key("joint_e.bearing_material.youngs_modulus_gpa", "joint.bearing_material.youngs_modulus", "float", GPA, 0, MODULUS_GPA),
    Key("joint_e.bearing_material.poisson_ratio", "joint.bearing_material.poisson_ratio", "float", 1, 0, 0.5,
        False, True),
    Key("joint_e.journal_material.yield_strength_mpa", "joint.journal_material.yield_strength", "float", MPA, 0, STRESS_MPA,
        doc="optional; peak contact pressure above 1.67 x this (first yield) is warned about"),
    Key("joint_e.bearing_material.yield_strength_mpa", "joint.bearing_material.yield_strength", "float", MPA, 0, STRESS_MPA,
        doc="optional; as for the journal (the smaller of the two counts)"),
    Key("joint_e.bearing_material.max_pressure_mpa", "joint.bearing_material.max_pressure", "float", MPA, 0, STRESS_MPA,
        doc="optional; the bushing's permitted projected pin pressure F / (d B): a peak above it is warned about"),
    Key("joint_e.bearing_material.max_pv_mpa_m_s", "joint.bearing_material.max_pv", "float", MPA, 0, 1e4,
        doc="optional; the bushing's permitted p x v (MPa x m/s): a cycle mean above it is warned about"),
    Key("joint_e.design_clearance_per_mille", "joint.design_clearance", "floats2", 1e-3, 0, 500, False,
        doc="optional; [low, high] design range of the radial clearance over the pin diameter, per mille "
            "(default [0.5, 1.0], a bushed pin in oscillating motion); outside it is warned about"),
    *WEAR_KEYS("joint_e", "joint"),
    *LUBRICATION_KEYS("joint_e", "joint"),
    # At least 1 rpm: a loom jogs at 10-60 rpm; slower, the journal rests in lasting contact for hours of machine
    # time, which the engines resolve in steps of microseconds (the reference scene: 179 steps for 0.1
    # revolution at 400 rpm, 2421 at 4 rpm; --speed-rpm 1e-9 ran 40 s without reaching 1 % of the run).
    Key("drive.speed_rpm", "drive.speed", "float", RPM, 1, 5000, False,
        doc="constant crank speed (1 rpm or more: a jog is 10-60 rpm)"),
    Key("drive.revolutions", "drive.revolutions", "float", 1, 0, 1000, doc="crank revolutions to simulate"),
    # The duty cycle (weftsim wear; docs/wear.md section 12), all optional.
    Key("duty.stops_per_hour", "duty.stops_per_hour", "float", 1, 0, 120, False,
        doc="loom stops per running hour (warp and weft breaks); each adds a simulated run-down and start-up's wear"),
    Key("duty.stop_minutes", "duty.stop_minutes", "float", 1, 0, 600, False,
        doc="mean standstill per stop, min (default 2.87: a warp break's repair, Haque et al. 2019)"),
    Key("duty.hours_per_day", "duty.hours_per_day", "float", 1, 0, 24, doc="scheduled hours a day (24: three shifts)"),
    Key("duty.days_per_week", "duty.days_per_week", "float", 1, 0, 7, doc="working days a week"),
    Key("duty.startup_revolutions", "duty.startup_revolutions", "float", 1, 0, 20,
        doc="crank revolutions of the start-up ramp from rest (default 1: full speed within the first pick)"),
    Key("duty.rundown_revolutions", "duty.rundown_revolutions", "float", 1, 0, 20,
        doc="crank revolutions of the run-down to rest (default 1)"),
    Key("solver.reference.method", "reference_solver.method", "str", choices=INTEGRATORS,
        doc="method of the reference engine: scipy's, or numba_* (compiled, docs/performance.md; numba_RODAS4 "
            "linearly implicit, numba_DOP853_RODAS4 implicit in contact); auto = numba_DOP853, or with friction "
            "numba_DOP853_RODAS4 at rtol <= 1e-6, or with a lubricated joint numba_RODAS4 (the fastest paths "
            "meeting the accuracy targets)"),
    Key("solver.reference.rtol", "reference_solver.rtol", "float", 1, TOLERANCE_FLOOR, 1e-2, False, doc="relative tolerance"),
    Key("solver.reference.atol", "reference_solver.atol", "float", 1, ATOL_FLOOR, 1e-2, False,
        doc="absolute tolerance"),
    Key("solver.reference.max_step_deg", "reference_solver.max_step", "float", DEG, 0, 90,
        doc="largest step, as crank angle"),
    Key("solver.exudyn.model", "exudyn_solver.model", "str", choices=EXUDYN_MODELS,
        doc="Exudyn model: auto = kinematic_tree unless the scene needs rigid_body (ideal joint); "
            "rigid_body = members 1-8, general; kinematic_tree = members 1-3 prescribed"),
    Key("solver.exudyn.step_control", "exudyn_solver.step_control", "str", choices=STEP_CONTROLS,
        doc="rigid_body model: adaptive (step from a local error estimate: large in free flight, small "
            "through impacts) or fixed (step_size_s)"),
    Key("solver.exudyn.local_error_m", "exudyn_solver.local_error", "float", 1, TOLERANCE_FLOOR, 1e-3, False,
        doc="rigid_body model, adaptive, and kinematic_tree, implicit: tolerance of the local error estimate "
            "of the journal centre at E per step (the implicit tree takes at most 3e-12 with an oil film: the run's "
            "path names the one used)"),
    Key("solver.exudyn.step_size_s", "exudyn_solver.step_size", "float", 1, 0, 1e-2,
        doc="generalized-alpha step when fixed (adaptive: unused; an ideal joint then steps 0.25 deg of "
            "crank, nothing to resolve)"),
    Key("solver.exudyn.spectral_radius", "exudyn_solver.spectral_radius", "float", 1, 0, 1, False, False,
        doc="rigid_body model: generalized-alpha spectral radius (<= 0.9 for smooth constraint torques; the "
            "kinematic tree's implicit solver takes 1, it has no constraints)"),
    Key("solver.exudyn.modified_newton", "exudyn_solver.modified_newton", "bool", doc="modified Newton"),
    Key("solver.exudyn.newton_relative_tolerance", "exudyn_solver.newton_relative_tolerance", "float", 1, TOLERANCE_FLOOR, 1e-2,
        False),
    Key("solver.exudyn.newton_max_iterations", "exudyn_solver.newton_max_iterations", "int", 1, 0, 1000),
    Key("solver.exudyn.callback", "exudyn_solver.callback", "str", choices=CALLBACK_ROUTES,
        doc="contact callback route; auto = fastest measured"),
    Key("solver.exudyn.tree_solver", "exudyn_solver.tree_solver", "str", choices=TREE_SOLVERS,
        doc="kinematic_tree model: explicit (explicit_method, automatic step size) or implicit "
            "(generalized-alpha, step error-controlled to local_error_m); auto = implicit with friction "
            "in the joint, explicit without (the faster of the two for each, docs/performance.md)"),
    Key("solver.exudyn.explicit_method", "exudyn_solver.explicit_method", "str", choices=EXPLICIT_METHODS,
        doc="kinematic_tree model: explicit solver with automatic step size"),
    Key("solver.exudyn.relative_tolerance", "exudyn_solver.relative_tolerance", "float", 1, TOLERANCE_FLOOR, 1e-2, False,
        doc="kinematic_tree model: relative tolerance of the step-size control"),
    Key("solver.exudyn.absolute_tolerance", "exudyn_solver.absolute_tolerance", "float", 1, TOLERANCE_FLOOR, 1e-2, False,
        doc="kinematic_tree model: absolute tolerance (joint angles in rad, rates in rad/s)"),
    Key("output.sample_deg", "output.sample_angle", "float", DEG, 0, 0.5, True, False,
        doc="output grid spacing in crank angle (0.5 deg or finer)"),
    Key("compare.first_contact_angle_deg", "compare.first_contact_angle", "float", DEG, 0, 360),
    Key("compare.first_revolution_peaks", "compare.first_revolution_peaks", "float", 1, 0, 1,
        doc="relative tolerance on first-revolution maxima"),
    Key("compare.rms", "compare.rms", "float", 1, 0, 1, doc="relative tolerance on RMS over revolutions 2..N"),
    Key("compare.percentile_99", "compare.percentile_99", "float", 1, 0, 1, doc="relative tolerance on 99th percentiles"),
    Key("compare.ideal_curves", "compare.ideal_curves", "float", 1, 0, 1,
        doc="ideal joint: largest difference at any sample, relative to the peak"),
    Key("limits.max_wall_time_s", "limits.max_wall_time", "float", 1, 0, 1e7, False,
        doc="wall-clock budget of one run; 0 = no limit (the run fails when it is spent)"),
    Key("limits.max_steps", "limits.max_steps", "int", 1, 0, 10**10, False,
        doc="budget of accepted solver steps; 0 = no limit"),
    Key("limits.max_penetration_ratio", "limits.max_penetration", "float", 1, 0, 1, True, False,
        doc="the run fails when the penetration exceeds this fraction of the journal radius"),
    Key("limits.min_step_s", "limits.min_step", "float", 1, 0, 1e-4,
        doc="step-size collapse: the smallest step either engine may take"),
    Key("limits.max_energy_error", "limits.max_energy_error", "float", 1, 0, 1, True, False,
        doc="the run fails when the energy balance misses by more than this fraction of the largest kinetic energy"),
    Key("limits.max_rapier_acceleration_m_s2", "limits.max_rapier_acceleration", "float", 1, 0, 1e6,
        doc="largest rapier acceleration a rapier head is built for (default 3000 m/s2); above it is warned about"),
    Key("limits.max_damping_ratio", "limits.max_damping_ratio", "float", 1, 0, 1e6, True,
        doc="damping force bound, multiple of xi x the elastic force (delta_dot / v_imp): <= 1 in an isolated "
            "impact and under max_approach (beyond it the run fails); the onset rule exceeds it (a warning)"),
)

def _joint_f_keys() -> tuple[Key, ...]:
    """The keys of [joint_f] (joint F, rod 4 - sector 5): those of [joint_e], for the scene's ``joint_f``,
    its wear table ``[joint_f.wear]`` included (``weftsim wear`` wears every loose joint; docs/wear.md)."""
    out = []
    for key in SCHEMA:
        if key.path.startswith("joint_e."):
            doc = "joint F: " + (key.doc or key.path.partition(".")[2])
            out.append(replace(key, path="joint_f." + key.path.partition(".")[2],
                               target="joint_f." + key.target.partition(".")[2], doc=doc))
    return tuple(out)


SCHEMA = SCHEMA + _joint_f_keys() + RAPIER_TAPE_KEYS + EXCHANGE_KEYS
_BY_PATH = {key.path: key for key in SCHEMA}
TOP_LEVEL = ("name", "description", "extends")
# Sections that describe the machine: a scene must give all their keys, itself or through
# `extends` (a missing one is an error, never a silent default).  Solver settings, output,
# compare tolerances and limits fall back to the defaults of weftsim.input.params.
REQUIRED_SECTIONS = ("mechanism", "inertia", "joint_e", "drive")
# Model options inside those sections that are not part of the machine: they default.
OPTIONAL = ("joint_e.impact_velocity_rule", "joint_e.journal_material.yield_strength_mpa",
            "joint_e.bearing_material.yield_strength_mpa", "joint_e.bearing_material.max_pressure_mpa",
            "joint_e.bearing_material.max_pv_mpa_m_s", "joint_e.design_clearance_per_mille",
            "joint_e.bushing_wall_mm") \
    + tuple(key.path for key in WEAR_KEYS("joint_e", "joint")) \
    + tuple(key.path for key in LUBRICATION_KEYS("joint_e", "joint"))
# [joint_f] is optional as a whole (absent: the ideal revolute joint at F).  Given a clearance > 0, F takes
# every key of [joint_e] its table does not give (weftsim.input.joint_keys).
REQUIRED = tuple(key.path for key in SCHEMA
                 if key.path.partition(".")[0] in REQUIRED_SECTIONS and key.path not in OPTIONAL)



def shown(text: str) -> str:
    """``text`` with every non-printable character escaped (``\\n``, ``\\x1b``, ...).

    Keys and names come from the user's file: a newline or a terminal escape sequence in one
    must not split a one-line message or reach the terminal raw.
    """
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def _set(scene: Any, target: str, value: Any) -> Any:
    """``scene`` (a Scene or one of its tables) with the dotted ``target`` set to ``value``."""
    head, _, rest = target.partition(".")
    if not rest:
        return replace(scene, **{head: value})
    inner = getattr(scene, head)
    if inner is None and head == "lubrication":  # the table's first key: the film starts from the defaults
        inner = params.Lubrication(viscosity=0.0)
    if inner is None and head == "rapier_tape":  # the table's first key: the tape starts from the defaults
        inner = params.RapierTape()
    if inner is None and head == "exchange":  # the table's first key: the exchange starts from the defaults
        inner = params.Exchange()
    return replace(scene, **{head: _set(inner, rest, value)})
