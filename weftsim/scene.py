"""Scene files: TOML in, validated :class:`weftsim.params.Scene` out.

A scene file may ``extends = "other.toml"`` (path relative to the file) or
``extends = "reference"`` (a bundled scene, :func:`bundled_scenes`) and then holds only
what differs; tables merge key by key.  A scene is named by a path or by the name of a
bundled scene (:func:`scene_source`): a regular file at the path wins, so a user's file
is never shadowed by a bundled scene of the same name.  Units live in the key names
(``_mm``, ``_deg``, ``_rpm``, ``_gpa``, ...) and are converted to SI here.  A scene
must give every key of the sections that describe the machine (:data:`REQUIRED_SECTIONS`),
itself or through ``extends``; settings (solver, output, compare, limits) default.  Every
problem is reported as one :class:`SceneError` naming the file, the key, the bad
value and what is allowed.  :data:`SCHEMA` is the single list of keys; the README's
scene reference is written from it.
"""

from __future__ import annotations

import difflib
import math
import os
import stat
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from weftsim import params
from weftsim.errors import SceneError

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


def WEAR_KEYS(table: str, joint: str) -> tuple[Key, ...]:  # noqa: N802 - a constant-like key factory
    """The ``[<table>.wear]`` keys of a clearance joint (weftsim wear; docs/wear.md), all optional."""
    return (
        # k spans 1e-2 (severe, dry) to below 1e-6 (Archard 1953; Rabinowicz 1995); hardness from soft
        # polymer bushings (~10 MPa) to ceramics and diamond (~1e5 MPa).  Beyond these the wear per update
        # dwarfs the clearance and the cycle extrapolation cannot follow it (issue 24).
        Key(f"{table}.wear.wear_coefficient", f"{joint}.wear.wear_coefficient", "float", 1, 0, 1e-2, True, False,
            doc="Archard's dimensionless wear coefficient k (default 1e-7, mild lubricated steel; 1e-2 severe dry wear)"),
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
        Key(at + "viscosity_mpa_s", to + "viscosity", "float", 1e-3, 0, None, False,
            doc="dynamic viscosity of the oil at operating temperature (ISO VG 220 at 60 C: ~80 mPa s); 0 = no film"),
        Key(at + "model", to + "model", "str", choices=params.FILM_MODELS,
            doc="film model: finite (finite-length bearing, default), short (Ocvirk), long (Sommerfeld) or "
                "short_half (Flores et al.'s short bearing)"),
        Key(at + "roughness_um", to + "roughness", "float", 1e-6, 0,
            doc="combined RMS roughness of journal and bearing (default 0.4 um, two ground surfaces)"),
        Key(at + "asperity_density_radius_roughness", to + "asperity_density_radius_roughness", "float", 1, 0, 1,
            False, doc="Greenwood-Tripp eta beta sigma (default 0.04); 0 = no asperity contact"),
        Key(at + "roughness_radius_ratio", to + "roughness_radius_ratio", "float", 1, 0, 1,
            doc="Greenwood-Tripp sigma / beta, RMS roughness over asperity summit radius (default 1e-3)"),
        Key(at + "boundary_friction_coefficient", to + "boundary_friction_coefficient", "float", 1, 0, 2, False,
            doc="friction coefficient on the asperity load (default 0.1)"),
        Key(at + "film_floor_ratio", to + "film_floor_ratio", "float", 1, 0, 4,
            doc="the film force is evaluated no closer than this many RMS roughnesses (default 1)"),
    )


SCHEMA: tuple[Key, ...] = (
    Key("mechanism.crank_inclination_deg", "geometry.crank_inclination", "float", DEG, 0, 90, True, True,
        doc="beta, arc A-B of the spherical 4R"),
    Key("mechanism.rocker_arm_angle_deg", "geometry.rocker_arm_angle", "float", DEG, -360, 360, False, False,
        doc="theta_OE0, angle of OE from +y towards +z at phi = 0"),
    Key("mechanism.l_oe_mm", "geometry.l_oe", "float", MM, 0, doc="rocker arm OE"),
    Key("mechanism.l_ef_mm", "geometry.l_ef", "float", MM, 0, doc="connecting rod EF"),
    Key("mechanism.l_fg_mm", "geometry.l_fg", "float", MM, 0, doc="sector arm FG"),
    Key("mechanism.l_og_mm", "geometry.l_og", "float", MM, 0, doc="frame O-G"),
    Key("mechanism.fourbar_branch", "geometry.fourbar_branch", "str", choices=tuple(BRANCHES),
        doc="assembly branch of the four-bar (docs/physics.md section 1: \"+\")"),
    Key("mechanism.sector_pitch_radius_mm", "geometry.sector_pitch_radius", "float", MM, 0, doc="d5"),
    Key("mechanism.pinion_pitch_radius_mm", "geometry.pinion_pitch_radius", "float", MM, 0, doc="d6"),
    Key("mechanism.rapier_gear_pitch_radius_mm", "geometry.rapier_gear_pitch_radius", "float", MM, 0, doc="d7"),
    Key("inertia.crank_inertia_kg_m2", "inertia.crank_inertia", "float", 1, 0, doc="J1 about A"),
    Key("inertia.coupler_mass_kg", "inertia.coupler_mass", "float", 1, 0, doc="m2 (centre of mass at O)"),
    Key("inertia.coupler_inertia_kg_m2", "inertia.coupler_inertia", "floats3", 1, 0,
        doc="principal inertia of the coupler about O in [b, c, b x c]"),
    Key("inertia.rocker_mass_kg", "inertia.rocker_mass", "float", 1, 0, doc="m3"),
    Key("inertia.rocker_com_mm", "inertia.rocker_com", "float", MM, None, doc="rocker centre of mass on OE from O"),
    Key("inertia.rocker_inertia_kg_m2", "inertia.rocker_inertia", "float", 1, 0, doc="J3 about D"),
    Key("inertia.rod_mass_kg", "inertia.rod_mass", "float", 1, 0, doc="m4 (centre of mass mid EF)"),
    Key("inertia.rod_inertia_kg_m2", "inertia.rod_inertia", "float", 1, 0, doc="J4 about its centre of mass"),
    Key("inertia.sector_inertia_kg_m2", "inertia.sector_inertia", "float", 1, 0, doc="J5 about G"),
    Key("inertia.pinion_gear_inertia_kg_m2", "inertia.pinion_gear_inertia", "float", 1, 0, doc="J67"),
    Key("inertia.rapier_mass_kg", "inertia.rapier_mass", "float", 1, 0, doc="m8"),
    Key("inertia.gravity_m_s2", "inertia.gravity", "float", 1, 0, doc="g along -z"),
    Key("joint_e.clearance_mm", "joint.clearance", "float", MM, 0, 5, False, doc="radial clearance c; 0 = ideal joint"),
    Key("joint_e.journal_radius_mm", "joint.journal_radius", "float", MM, 0, doc="R_j"),
    Key("joint_e.bearing_length_mm", "joint.bearing_length", "float", MM, 0, doc="L_b"),
    Key("joint_e.law", "joint.law", "str", doc="contact force law (see weftsim.contact.LAWS)"),
    Key("joint_e.restitution", "joint.restitution", "float", 1, 0, 1, True, False, doc="coefficient of restitution ce"),
    Key("joint_e.friction_coefficient", "joint.friction_coefficient", "float", 1, 0, 2, False,
        doc="mu of the modified Coulomb law; 0 = off"),
    Key("joint_e.friction_velocities_m_s", "joint.friction_velocities", "floats2", 1, 0,
        doc="[v0, v1] of the friction ramp, v0 < v1"),
    Key("joint_e.min_impact_velocity_m_s", "joint.min_impact_velocity", "float", 1, 0,
        doc="floor on the held impact velocity"),
    Key("joint_e.impact_velocity_rule", "joint.impact_velocity_rule", "str", choices=IMPACT_VELOCITY_RULES,
        doc="held impact velocity: largest approach rate since onset, or the onset value alone"),
    Key("joint_e.journal_material.youngs_modulus_gpa", "joint.journal_material.youngs_modulus", "float", GPA, 0),
    Key("joint_e.journal_material.poisson_ratio", "joint.journal_material.poisson_ratio", "float", 1, 0, 0.5,
        False, True),
    Key("joint_e.bearing_material.youngs_modulus_gpa", "joint.bearing_material.youngs_modulus", "float", GPA, 0),
    Key("joint_e.bearing_material.poisson_ratio", "joint.bearing_material.poisson_ratio", "float", 1, 0, 0.5,
        False, True),
    Key("joint_e.journal_material.yield_strength_mpa", "joint.journal_material.yield_strength", "float", MPA, 0,
        doc="optional; peak contact pressure above 1.67 x this (first yield) is warned about"),
    Key("joint_e.bearing_material.yield_strength_mpa", "joint.bearing_material.yield_strength", "float", MPA, 0,
        doc="optional; as for the journal (the smaller of the two counts)"),
    Key("joint_e.bearing_material.max_pressure_mpa", "joint.bearing_material.max_pressure", "float", MPA, 0,
        doc="optional; the bushing's permitted projected pin pressure F / (d B): a peak above it is warned about"),
    Key("joint_e.bearing_material.max_pv_mpa_m_s", "joint.bearing_material.max_pv", "float", MPA, 0,
        doc="optional; the bushing's permitted p x v (MPa x m/s): a cycle mean above it is warned about"),
    Key("joint_e.design_clearance_per_mille", "joint.design_clearance", "floats2", 1e-3, 0, None, False,
        doc="optional; [low, high] design range of the radial clearance over the pin diameter, per mille "
            "(default [0.5, 1.0], a bushed pin in oscillating motion); outside it is warned about"),
    *WEAR_KEYS("joint_e", "joint"),
    *LUBRICATION_KEYS("joint_e", "joint"),
    Key("drive.speed_rpm", "drive.speed", "float", RPM, 0, 5000, doc="constant crank speed"),
    Key("drive.revolutions", "drive.revolutions", "float", 1, 0, 1000, doc="crank revolutions to simulate"),
    Key("solver.reference.method", "reference_solver.method", "str", choices=INTEGRATORS,
        doc="method of the reference engine: scipy's, or numba_* (compiled, docs/performance.md; numba_RODAS4 "
            "linearly implicit, numba_DOP853_RODAS4 implicit in contact); auto = numba_DOP853, or with friction "
            "numba_DOP853_RODAS4 at rtol <= 1e-6, or with a lubricated joint numba_RODAS4 (the fastest paths "
            "meeting the accuracy targets)"),
    Key("solver.reference.rtol", "reference_solver.rtol", "float", 1, 0, 1e-2, doc="relative tolerance"),
    Key("solver.reference.atol", "reference_solver.atol", "float", 1, 0, 1e-2, doc="absolute tolerance"),
    Key("solver.reference.max_step_deg", "reference_solver.max_step", "float", DEG, 0, 90,
        doc="largest step, as crank angle"),
    Key("solver.exudyn.model", "exudyn_solver.model", "str", choices=EXUDYN_MODELS,
        doc="Exudyn model: auto = kinematic_tree unless the scene needs rigid_body (ideal joint); "
            "rigid_body = members 1-8, general; kinematic_tree = members 1-3 prescribed"),
    Key("solver.exudyn.step_control", "exudyn_solver.step_control", "str", choices=STEP_CONTROLS,
        doc="rigid_body model: adaptive (step from a local error estimate: large in free flight, small "
            "through impacts) or fixed (step_size_s)"),
    Key("solver.exudyn.local_error_m", "exudyn_solver.local_error", "float", 1, 0, 1e-3,
        doc="rigid_body model, adaptive, and kinematic_tree, implicit: tolerance of the local error estimate "
            "of the journal centre at E per step"),
    Key("solver.exudyn.step_size_s", "exudyn_solver.step_size", "float", 1, 0, 1e-2,
        doc="generalized-alpha step when fixed (adaptive: unused; an ideal joint then steps 0.25 deg of "
            "crank, nothing to resolve)"),
    Key("solver.exudyn.spectral_radius", "exudyn_solver.spectral_radius", "float", 1, 0, 1, False, False,
        doc="rigid_body model: generalized-alpha spectral radius (<= 0.9 for smooth constraint torques; the "
            "kinematic tree's implicit solver takes 1, it has no constraints)"),
    Key("solver.exudyn.modified_newton", "exudyn_solver.modified_newton", "bool", doc="modified Newton"),
    Key("solver.exudyn.newton_relative_tolerance", "exudyn_solver.newton_relative_tolerance", "float", 1, 0, 1e-2),
    Key("solver.exudyn.newton_max_iterations", "exudyn_solver.newton_max_iterations", "int", 1, 0, 1000),
    Key("solver.exudyn.callback", "exudyn_solver.callback", "str", choices=CALLBACK_ROUTES,
        doc="contact callback route; auto = fastest measured"),
    Key("solver.exudyn.tree_solver", "exudyn_solver.tree_solver", "str", choices=TREE_SOLVERS,
        doc="kinematic_tree model: explicit (explicit_method, automatic step size) or implicit "
            "(generalized-alpha, step error-controlled to local_error_m); auto = implicit with friction "
            "in the joint, explicit without (the faster of the two for each, docs/performance.md)"),
    Key("solver.exudyn.explicit_method", "exudyn_solver.explicit_method", "str", choices=EXPLICIT_METHODS,
        doc="kinematic_tree model: explicit solver with automatic step size"),
    Key("solver.exudyn.relative_tolerance", "exudyn_solver.relative_tolerance", "float", 1, 0, 1e-2,
        doc="kinematic_tree model: relative tolerance of the step-size control"),
    Key("solver.exudyn.absolute_tolerance", "exudyn_solver.absolute_tolerance", "float", 1, 0, 1e-2,
        doc="kinematic_tree model: absolute tolerance (joint angles in rad, rates in rad/s)"),
    Key("output.sample_deg", "output.sample_angle", "float", DEG, 0, 0.5, True, False,
        doc="output grid spacing in crank angle (0.5 deg or finer)"),
    Key("compare.first_contact_angle_deg", "compare.first_contact_angle", "float", DEG, 0),
    Key("compare.first_revolution_peaks", "compare.first_revolution_peaks", "float", 1, 0,
        doc="relative tolerance on first-revolution maxima"),
    Key("compare.rms", "compare.rms", "float", 1, 0, doc="relative tolerance on RMS over revolutions 2..N"),
    Key("compare.percentile_99", "compare.percentile_99", "float", 1, 0, doc="relative tolerance on 99th percentiles"),
    Key("compare.ideal_curves", "compare.ideal_curves", "float", 1, 0,
        doc="ideal joint: largest difference at any sample, relative to the peak"),
    Key("limits.max_wall_time_s", "limits.max_wall_time", "float", 1, 0, None, False,
        doc="wall-clock budget of one run; 0 = no limit (the run fails when it is spent)"),
    Key("limits.max_steps", "limits.max_steps", "int", 1, 0, None, False,
        doc="budget of accepted solver steps; 0 = no limit"),
    Key("limits.max_penetration_ratio", "limits.max_penetration", "float", 1, 0, 1, True, False,
        doc="the run fails when the penetration exceeds this fraction of the journal radius"),
    Key("limits.min_step_s", "limits.min_step", "float", 1, 0, 1e-4,
        doc="step-size collapse: the smallest step either engine may take"),
    Key("limits.max_energy_error", "limits.max_energy_error", "float", 1, 0, 1, True, False,
        doc="the run fails when the energy balance misses by more than this fraction of the largest kinetic energy"),
    Key("limits.max_rapier_acceleration_m_s2", "limits.max_rapier_acceleration", "float", 1, 0,
        doc="largest rapier acceleration a rapier head is built for (default 3000 m/s2); above it is warned about"),
    Key("limits.max_damping_ratio", "limits.max_damping_ratio", "float", 1, 0, None, True,
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


SCHEMA = SCHEMA + _joint_f_keys()
_BY_PATH = {key.path: key for key in SCHEMA}
TOP_LEVEL = ("name", "description", "extends")
# Sections that describe the machine: a scene must give all their keys, itself or through
# `extends` (a missing one is an error, never a silent default).  Solver settings, output,
# compare tolerances and limits fall back to the defaults of weftsim.params.
REQUIRED_SECTIONS = ("mechanism", "inertia", "joint_e", "drive")
# Model options inside those sections that are not part of the machine: they default.
OPTIONAL = ("joint_e.impact_velocity_rule", "joint_e.journal_material.yield_strength_mpa",
            "joint_e.bearing_material.yield_strength_mpa", "joint_e.bearing_material.max_pressure_mpa",
            "joint_e.bearing_material.max_pv_mpa_m_s", "joint_e.design_clearance_per_mille") \
    + tuple(key.path for key in WEAR_KEYS("joint_e", "joint")) \
    + tuple(key.path for key in LUBRICATION_KEYS("joint_e", "joint"))
# [joint_f] is optional as a whole (absent: the ideal revolute joint at F).  Given a clearance > 0, F takes
# every key of [joint_e] its table does not give (weftsim.joint_keys).
REQUIRED = tuple(key.path for key in SCHEMA
                 if key.path.partition(".")[0] in REQUIRED_SECTIONS and key.path not in OPTIONAL)


# A scene file is a few kilobytes (models/reference.toml: 2.5 kB).  Anything beyond this bound
# is not a scene (a log, an image, /dev/zero): it is refused before it is read into memory.
MAX_SCENE_BYTES = 1 << 20
# Longest `extends` chain: the deepest in models/ is 2 files; 64 leaves room for any layering
# a user builds and stops a runaway chain with one line instead of a RecursionError.
MAX_EXTENDS_DEPTH = 64


def shown(text: str) -> str:
    """``text`` with every non-printable character escaped (``\\n``, ``\\x1b``, ...).

    Keys and names come from the user's file: a newline or a terminal escape sequence in one
    must not split a one-line message or reach the terminal raw.
    """
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def _spelling(table: tuple[str, ...], name: str) -> str:
    """Where a key is written in the file: ``clearance_mm in [joint_e]`` or ``"a.b" at the top level``."""
    key = f'"{name}"' if "." in name else name
    return shown(f"{key} in [{'.'.join(table)}]" if table else f"{key} at the top level")


def _flatten(table: dict, where: str, prefix: tuple[str, ...] = (),
             seen: dict[str, str] | None = None) -> dict[str, Any]:
    """Dotted keys of a TOML table; one key given twice (a quoted dotted key at one level and
    the same key in its table) is a :class:`SceneError` naming both places."""
    seen = {} if seen is None else seen
    flat = {}
    for name, value in table.items():
        path = ".".join(prefix + (name,))
        if isinstance(value, dict):
            flat.update(_flatten(value, where, prefix + (name,), seen))
            continue
        if path in seen:
            raise SceneError(f"{where}: key '{shown(path)}' is given twice, as {seen[path]} and as "
                             f"{_spelling(prefix, name)}; give it once")
        seen[path] = _spelling(prefix, name)
        flat[path] = value
    return flat


def _read_toml(path: Path) -> dict:
    """The TOML table of one scene file: a regular file of at most :data:`MAX_SCENE_BYTES`.

    Checked with ``stat`` before opening, so a FIFO (which would block) or a device such as
    ``/dev/zero`` (which never ends) is refused without being read.
    """
    try:
        info = path.stat()
    except FileNotFoundError:
        raise SceneError(f"{path}: scene file not found") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot be read ({exc.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        raise SceneError(f"{path}: is a directory, expected a scene file (.toml)")
    if not stat.S_ISREG(info.st_mode):
        raise SceneError(f"{path}: is not a regular file (a pipe, device or socket); a scene must be a "
                         "regular .toml file")
    if info.st_size > MAX_SCENE_BYTES:
        raise SceneError(f"{path}: is {info.st_size} bytes, more than a scene file's {MAX_SCENE_BYTES} "
                         "bytes; a scene file holds only keys and values (.toml)")
    try:
        with path.open("rb") as file:
            data = file.read(MAX_SCENE_BYTES + 1)  # bounded even if the file grows after the stat
        if len(data) > MAX_SCENE_BYTES:
            raise SceneError(f"{path}: grew beyond a scene file's {MAX_SCENE_BYTES} bytes while being read")
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot be read ({exc})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc})") from None


def bundled_directory() -> Path | None:
    """The directory of the bundled scene files, or None if this installation has none.

    An installed weftsim carries them as the package data ``weftsim/scenes`` (the build maps
    the repository's ``models/`` there, see ``setup.py``); a source checkout, run from the tree
    or installed in editable mode, reads ``models/`` beside the package itself.
    """
    package = Path(__file__).resolve().parent
    installed, checkout = package / "scenes", package.parent / "models"
    if (installed / "reference.toml").is_file():
        return installed
    if (checkout / "reference.toml").is_file() and (package.parent / "pyproject.toml").is_file():
        return checkout
    return None


def bundled_scenes() -> list[str]:
    """Names of the bundled scenes, sorted: the file's path below the scene directory without ``.toml``
    (``"reference"``, ``"paper/clearance_0p50mm_400rpm"``)."""
    root = bundled_directory()
    if root is None:
        return []
    return sorted(p.relative_to(root).with_suffix("").as_posix() for p in root.rglob("*.toml") if p.is_file())


def bundled_scene_path(name: str) -> Path:
    """The file of the bundled scene ``name``.

    Raises
    ------
    SceneError
        If no bundled scene has that name (the message lists them, closest first).
    """
    names = bundled_scenes()
    if name not in names:
        raise SceneError(f"no bundled scene named {shown(name)!r}; {_bundled_hint(name, names)}")
    root = bundled_directory()
    assert root is not None  # names is not empty
    return root / (name + ".toml")


def _bundled_hint(name: str, names: list[str]) -> str:
    """'did you mean ...? bundled scenes: ...' for an unknown scene name."""
    if not names:
        return "this installation has no bundled scenes"
    near = difflib.get_close_matches(name.removesuffix(".toml"), names, n=2, cutoff=0.6)
    mean = f"did you mean {' or '.join(near)}? " if near else ""
    return f"{mean}bundled scenes: {', '.join(names)} ('weftsim scenes' lists them)"


def scene_source(scene: str | os.PathLike, base: Path | None = None) -> Path:
    """The file a scene argument names: a path, or the name of a bundled scene.

    A string names a regular file if one exists at that path (relative to ``base``, default the
    current directory); otherwise a bundled scene of that name (``"reference"``,
    ``"paper/clearance_0p50mm_400rpm"``).  A :class:`os.PathLike` is always a path.  Anything else
    is returned as a path, so reading it reports what is wrong (not found, a directory, a pipe).

    Raises
    ------
    SceneError
        If nothing exists at the path and no bundled scene has that name.
    """
    if not isinstance(scene, (str, os.PathLike)):
        raise SceneError(f"a scene is a path or the name of a bundled scene, got {type(scene).__name__} "
                         f"{shown(repr(scene))[:80]}")
    path = Path(scene) if base is None else base / scene
    if isinstance(scene, os.PathLike) or path.is_file():
        return path
    if scene in bundled_scenes():
        return bundled_scene_path(scene)
    if os.path.lexists(path):  # a directory, pipe or device: reading it says so
        return path
    raise SceneError(f"{shown(str(path))}: scene file not found, and no bundled scene has that name; "
                     f"{_bundled_hint(scene, bundled_scenes())}")


def scene_description(path: Path) -> str:
    """The ``description`` of a scene file (empty if it gives none or cannot be read)."""
    try:
        description = _read_toml(path).get("description", "")
    except SceneError:
        return ""
    return description if isinstance(description, str) else ""


def _read_merged(path: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """Flattened keys of a scene and its ``extends`` chain, and the file each key came from.

    The chain is followed in a loop (not by recursion), at most :data:`MAX_EXTENDS_DEPTH` files.
    """
    chain: list[tuple[Path, dict[str, Any]]] = []
    path = path.resolve()
    while True:
        if path in [p for p, _ in chain]:
            raise SceneError(f"{path}: 'extends' loops back to itself via {[str(p) for p, _ in chain]}")
        if len(chain) == MAX_EXTENDS_DEPTH:
            raise SceneError(f"{chain[0][0]}: the 'extends' chain is longer than {MAX_EXTENDS_DEPTH} files "
                             f"(reached {path}); a scene may extend at most {MAX_EXTENDS_DEPTH} files deep")
        flat = _flatten(_read_toml(path), str(path))
        chain.append((path, flat))
        if "extends" not in flat:
            break
        parent = flat.pop("extends")
        if not isinstance(parent, str):
            raise SceneError(f"{path}: key 'extends' must be a path or the name of a bundled scene, got {parent!r}")
        try:
            path = scene_source(parent, path.parent).resolve()
        except SceneError as exc:
            raise SceneError(f"{path}: key 'extends' = {shown(repr(parent))}: {exc}") from None
    merged, origin = {}, {}
    for index, (path, flat) in enumerate(reversed(chain)):
        if index:  # a base file's name and description do not describe the scene extending it
            merged.pop("name", None)
            merged.pop("description", None)
        merged.update(flat)
        origin.update({key: path for key in flat})
    return merged, origin


def _convert(key: Key, value: Any, where: str) -> Any:
    def fail(expect: str) -> SceneError:
        return SceneError(f"{where}: key '{key.path}' {expect}, got {value!r}")

    if key.kind == "bool":
        if not isinstance(value, bool):
            raise fail("must be true or false")
        return value
    if key.kind == "str":
        if not isinstance(value, str):
            raise fail("must be a string")
        if key.choices and value not in key.choices:
            raise fail(f"must be {key.allowed()}")
        return value
    if key.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise fail("must be a whole number")
        numbers = [value]
    elif key.kind == "float":
        numbers = [value]
    else:
        size = {"floats2": 2, "floats3": 3}[key.kind]
        if not isinstance(value, list) or len(value) != size:
            raise fail(f"must be a list of {size} numbers")
        numbers = value
    for number in numbers:
        if isinstance(number, bool) or not isinstance(number, (int, float)):
            raise fail("must be a number")
        try:
            finite = math.isfinite(number) and math.isfinite(float(number) * key.scale)
        except OverflowError:  # an integer beyond any float
            finite = False
        if not finite:
            raise fail("must be a finite number (also in SI units)")
        low_bad = key.low is not None and (number <= key.low if key.low_open else number < key.low)
        high_bad = key.high is not None and (number >= key.high if key.high_open else number > key.high)
        if low_bad or high_bad:
            raise fail(f"must be {key.allowed()}")
    if key.target in ("joint.friction_velocities", "joint_f.friction_velocities") and not numbers[0] < numbers[1]:
        # Checked here, not with the other cross-key checks: ClearanceJoint itself refuses v0 >= v1.
        raise fail("must have v0 < v1")
    if key.target in ("joint.design_clearance", "joint_f.design_clearance") and not numbers[0] < numbers[1]:
        raise fail("must be [low, high] with low < high")
    if key.kind == "int":
        return value
    scaled = tuple(float(n) * key.scale for n in numbers)
    return scaled[0] if key.kind == "float" else scaled


def _set(scene: params.Scene, target: str, value: Any) -> params.Scene:
    head, _, rest = target.partition(".")
    if not rest:
        return replace(scene, **{head: value})
    inner = getattr(scene, head)
    if inner is None and head == "lubrication":  # the table's first key: the film starts from the defaults
        inner = params.Lubrication(viscosity=0.0)
    return replace(scene, **{head: _set(inner, rest, value)})


def _set_checked(scene: params.Scene, target: str, value: Any, where: str) -> params.Scene:
    """:func:`_set`, with a cross-field refusal of the parameter objects (ValueError) as a SceneError."""
    try:
        return _set(scene, target, value)
    except ValueError as exc:
        raise SceneError(f"{where}: {exc}") from None


LUBRICATION_TABLES = (("joint_e", "joint"), ("joint_f", "joint_f"))


def _check_lubrication_given(keys, where: str, before: params.Scene | None = None) -> None:
    """A ``[<joint>.lubrication]`` table must name ``viscosity_mpa_s`` (unless ``before`` already has a film)."""
    keys = list(keys)
    for table, attr in LUBRICATION_TABLES:
        prefix = f"{table}.lubrication."
        if before is not None and getattr(before, attr).lubrication is not None:
            continue
        if any(k.startswith(prefix) for k in keys) and prefix + "viscosity_mpa_s" not in keys:
            raise SceneError(f"{where}: missing required key '{prefix}viscosity_mpa_s'; a [{table}.lubrication] "
                             "table must give the oil's viscosity (the other lubrication keys default)")


def _check_scene(scene: params.Scene, where: str, origin: dict[str, Path]) -> None:
    """Cross-key checks: law names, clearance below the journal radius, linkage assembly."""
    from weftsim.contact import LAWS

    def at(key: str) -> str:
        return str(origin.get(key, where))

    for table, joint in (("joint_e", scene.joint), ("joint_f", scene.joint_f)):
        if table == "joint_f" and joint.is_ideal:
            continue  # the ideal joint at F: its other keys describe nothing
        law, clearance = f"{table}.law", f"{table}.clearance_mm"
        if joint.law not in LAWS:
            raise SceneError(f"{at(law)}: key '{law}' must be one of {', '.join(sorted(LAWS))}, got {joint.law!r}")
        if joint.clearance >= joint.journal_radius:
            raise SceneError(
                f"{at(clearance)}: key '{clearance}' must be smaller than the journal radius "
                f"{joint.journal_radius / MM:g} mm, got {joint.clearance / MM:g}"
            )
    if scene.output.sample_angle / scene.drive.speed > scene.drive.end_time:
        raise SceneError(f"{at('drive.revolutions')}: key 'drive.revolutions' is shorter than one output sample")
    from weftsim.kinematics import assembly_failure_angle

    angle = assembly_failure_angle(scene.geometry)
    if angle is not None:
        raise SceneError(
            f"{where}: the linkage cannot be assembled at crank angle {math.degrees(angle):.2f} deg "
            "(the four-bar O-E-F-G does not close: check mechanism.l_oe_mm, l_ef_mm, l_fg_mm, l_og_mm "
            "and rocker_arm_angle_deg)"
        )


def _known(path: str, where: str) -> Key:
    """The schema key of a dotted path, or a SceneError listing the keys allowed there."""
    key = _BY_PATH.get(path)
    if key is None:
        section = path.rpartition(".")[0]
        near = [k.path for k in SCHEMA if k.path.rpartition(".")[0] == section] or sorted(
            {k.path.partition(".")[0] for k in SCHEMA}
        )
        close = difflib.get_close_matches(path, list(_BY_PATH), n=1, cutoff=0.75)
        mean = f"did you mean '{close[0]}'? " if close else ""
        raise SceneError(f"{where}: unknown key '{shown(path)}'; {mean}allowed here: {', '.join(near)}")
    return key


def scene_from_keys(flat: dict[str, Any], where: str = "scene", origin: dict[str, Path] | None = None) -> params.Scene:
    """Validated :class:`Scene` from flattened dotted keys (file values, file units)."""
    from weftsim.joint_keys import inherit_joint_f

    origin = dict(origin or {})
    flat, inherited = inherit_joint_f(flat)
    origin.update({"joint_f." + rest: origin["joint_e." + rest] for rest in inherited if "joint_e." + rest in origin})
    name = flat.get("name", "scene")
    if not isinstance(name, str):
        raise SceneError(f"{where}: key 'name' must be a string, got {name!r}")
    if not name or not name.isprintable():  # it heads every report line and figure title
        raise SceneError(f"{where}: key 'name' must be a non-empty line of printable characters "
                         f"(no newline or escape sequence), got {name!r}")
    scene = params.Scene(name=name, source=where)
    for path, value in flat.items():
        if path in TOP_LEVEL:
            continue
        src = str(origin.get(path, where))
        key = _known(path, src)
        value = _convert(key, value, src)
        if key.path == "mechanism.fourbar_branch":
            value = BRANCHES[value]
        scene = _set_checked(scene, key.target, value, src)
    scene = replace(scene, joint_f_inherits=inherited)
    _check_lubrication_given(flat, where)
    _check_scene(scene, where, origin)
    return scene


def load_scene(path: str | os.PathLike, overrides: dict[str, Any] | None = None,
               overrides_from: str = "command line", *, refuse_ideal_keys: bool = True) -> params.Scene:
    """Read, merge (``extends``), override and validate a scene file.

    Joint F given a clearance takes every key of ``[joint_e]`` its table does not give
    (:func:`weftsim.joint_keys.inherit_joint_f`); ``scene.joint_f_inherits`` names them.

    Parameters
    ----------
    path : str or path-like
        The TOML scene file, or the name of a bundled scene (:func:`scene_source`).
    overrides : dict, optional
        Dotted file keys with file-unit values, e.g. ``{"drive.speed_rpm": 500}``,
        applied after the file (the command-line flags use this).
    overrides_from : str
        Where the overrides came from, as error messages name it.
    refuse_ideal_keys : bool
        Refuse an override of a joint key (other than its ``clearance_mm``) at a joint that is ideal
        in the resulting scene: it would change nothing (:mod:`weftsim.joint_keys`).  A sweep passes
        False and checks its cells together.

    Raises
    ------
    SceneError
        Naming the file (or "command line"), the key, the bad value and what is allowed;
        or the required keys (sections :data:`REQUIRED_SECTIONS`) that neither the file
        nor the files it extends give; or a joint key set on a joint that is ideal.
    """
    from weftsim.joint_keys import describes_joint, ideal_joint_keys, ideal_key_message

    path = scene_source(path)
    flat, origin = _read_merged(path)
    flat.setdefault("name", path.stem)
    for dotted, value in (overrides or {}).items():
        if value is None:
            continue
        flat[dotted] = value
        origin[dotted] = Path(overrides_from)
    for dotted in flat:  # a misspelt key is reported as such, not as the missing one it stands for
        if dotted not in TOP_LEVEL:
            _known(dotted, str(origin.get(dotted, path)))
    if "joint_f.clearance_mm" not in flat:  # a [joint_f] table without a clearance describes an ideal joint
        stray = [key for key in flat if key.startswith("joint_f.") and describes_joint(key)
                 and key not in (overrides or {})]  # overrides: checked on the scene below
        if stray:
            raise SceneError(ideal_key_message(stray[0], str(origin.get(stray[0], path))))
    missing = [key for key in REQUIRED if key not in flat]
    if missing:
        raise SceneError(
            f"{path}: missing required keys {', '.join(missing)}; a scene must give every key of "
            f"[{'], ['.join(REQUIRED_SECTIONS)}] itself or through `extends = \"reference.toml\"` "
            "(then it holds only what differs)"
        )
    scene = scene_from_keys(flat, str(path), origin)
    given = [key for key, value in (overrides or {}).items() if value is not None]
    idle = ideal_joint_keys(scene, given) if refuse_ideal_keys else []
    if idle:
        raise SceneError(ideal_key_message(idle[0], overrides_from))
    return scene


def to_file_keys(scene: params.Scene) -> dict[str, Any]:
    """The scene as flattened file keys in file units (for summaries and provenance)."""
    out: dict[str, Any] = {"name": scene.name}
    for key in SCHEMA:
        obj: Any = scene
        for part in key.target.split("."):
            obj = getattr(obj, part)
            if obj is None:
                break  # a dry joint's lubrication keys: None, as any unset optional key
        if obj is None:  # an optional key the scene does not give
            pass
        elif key.path == "mechanism.fourbar_branch":
            obj = "+" if obj > 0 else "-"
        elif key.kind in ("float", "floats2", "floats3"):
            obj = obj / key.scale if key.kind == "float" else [v / key.scale for v in obj]
        out[key.path] = obj
    return out


def apply_overrides(scene: params.Scene, overrides: dict[str, Any], where: str = "command line",
                    refuse_ideal_keys: bool = True) -> params.Scene:
    """``scene`` with dotted file keys replaced (file units), validated as :func:`load_scene` validates.

    The same scene :func:`load_scene` gives for a file and these overrides, without reading
    the file again: a sweep validates thousands of cells against one base scene this way.

    Keys joint F takes from joint E follow E's overrides (:func:`weftsim.joint_keys.resync_joint_f`).

    Raises
    ------
    SceneError
        For an unknown key, a bad value or a scene that fails the cross-key checks, naming ``where``;
        with ``refuse_ideal_keys``, for a joint key set on a joint that is ideal (it changes nothing).
    """
    from weftsim.joint_keys import ideal_joint_keys, ideal_key_message, resync_joint_f

    before = scene
    for dotted, value in overrides.items():
        if value is None:
            continue
        if dotted == "name":
            if not isinstance(value, str):
                raise SceneError(f"{where}: key 'name' must be a string, got {value!r}")
            scene = replace(scene, name=value)
            continue
        key = _known(dotted, where)
        value = _convert(key, value, where)
        if key.path == "mechanism.fourbar_branch":
            value = BRANCHES[value]
        scene = _set_checked(scene, key.target, value, where)
    scene = resync_joint_f(scene, {key for key, value in overrides.items() if value is not None})
    _check_lubrication_given([k for k, v in overrides.items() if v is not None], where, before)
    _check_scene(scene, where, {})
    idle = ideal_joint_keys(scene, [key for key, value in overrides.items() if value is not None])
    if idle and refuse_ideal_keys:
        raise SceneError(ideal_key_message(idle[0], where))
    return scene
