"""What a stored wear state is: its file name, its response columns, the scene identity it must match, and the
error of a state that cannot be resumed.

Read by :mod:`weftsim.wear.store` (which writes the state) and :mod:`weftsim.wear.resume` (which reads it back as
untrusted input), so that neither imports the other's caller: the store calls the reader, one way.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from weftsim.errors import WearError

if TYPE_CHECKING:
    from weftsim.input.params import Scene

STATE = "wear_state.npz"
# Response statistics of an update (extrapolate._response, _sliding): the mechanism's, then each joint's
# (NaN for a joint that does not wear).
MECHANISM_RESPONSE = ("rapier_acceleration_rms_m_s2", "rapier_acceleration_p99_m_s2", "driving_torque_rms_Nm",
                      "driving_torque_p99_Nm", "solver_rtol", "backoffs_after")
JOINT_RESPONSE = ("contact_force_{j}_mean_N", "contact_force_{j}_p99_N", "contact_force_{j}_max_N",
                  "film_ratio_min_{j}", "film_ratio_mean_{j}", "mixed_fraction_{j}", "sliding_distance_per_rev_{j}_m",
                  "sliding_work_per_rev_{j}_J", "contact_force_sliding_mean_{j}_N")
JOINTS = ("e", "f")
# Columns added after the layout above was first stored, appended so that a state written before them loads
# (their values NaN, weftsim.wear.resume): the asperities' share of the sliding work (the mixed regime's k).
LATER_RESPONSE = ("asperity_work_per_rev_{j}_J", "stop_start_volume_{j}_mm3", "stop_start_share_{j}",
                  "stop_start_start_up_share_{j}", "film_temperature_{j}_C", "roughness_{j}_um")
EARLIER_RESPONSE = MECHANISM_RESPONSE + tuple(name.format(j=j) for j in JOINTS for name in JOINT_RESPONSE)
RESPONSE = EARLIER_RESPONSE + tuple(name.format(j=j) for j in JOINTS for name in LATER_RESPONSE)
# The columns of a state written before the joints were named (joint E alone), in their stored order, and
# their names now: such a state still loads (weftsim.wear.resume).
LEGACY_RESPONSE = ("rapier_acceleration_rms_m_s2", "rapier_acceleration_p99_m_s2", "driving_torque_rms_Nm",
                   "driving_torque_p99_Nm", "contact_force_mean_N", "contact_force_p99_N", "contact_force_max_N",
                   "solver_rtol", "film_ratio_min", "film_ratio_mean", "mixed_fraction", "sliding_distance_per_rev_m",
                   "sliding_work_per_rev_J", "contact_force_sliding_mean_N", "backoffs_after")
LEGACY_NAMES = {"contact_force_mean_N": "contact_force_e_mean_N", "contact_force_p99_N": "contact_force_e_p99_N",
                "contact_force_max_N": "contact_force_e_max_N", "film_ratio_min": "film_ratio_min_e",
                "film_ratio_mean": "film_ratio_mean_e", "mixed_fraction": "mixed_fraction_e",
                "sliding_distance_per_rev_m": "sliding_distance_per_rev_e_m",
                "sliding_work_per_rev_J": "sliding_work_per_rev_e_J",
                "contact_force_sliding_mean_N": "contact_force_sliding_mean_e_N",
                **{name: name for name in MECHANISM_RESPONSE}}
# Per-joint arrays of the state, stored as NAME_<joint>.
PARTS = ("bearing", "journal", "rate_bearing", "rate_journal", "volume_rate")


class StateMismatch(WearError):
    """The directory's stored state cannot be resumed: another scene or other wear settings, a damaged
    or edited file (:mod:`weftsim.wear.resume`), or more hours than asked for."""


def scene_identity(scene: Scene) -> str:
    """The scene's file keys as canonical JSON: what a stored state must match to be resumed.

    An ideal joint F's ``[joint_f.wear]`` keys are left out: they change nothing, and a state written before F
    could wear (which did not know them) stays the same scene's; so are the oil's and its heat balance's keys of a
    joint that names no oil (a fixed viscosity or a dry joint), for a state written before they existed.  So are the
    ``[rapier_tape]`` keys of a scene without a tape and the ``[exchange]`` keys of a scene without an exchange (all
    unset), for a state written before the tape or the exchange existed, and
    an unset ``bushing_wall_mm`` (the cylindrical law's, which refuses a joint without it), for a state written
    before that key existed, and the elastic film's keys at their defaults (:data:`ELASTIC_DEFAULTS`).
    """
    from weftsim.input.scene import to_file_keys

    from weftsim.input.scene import HEAT_KEYS

    keys = to_file_keys(scene)
    if scene.joint_f.is_ideal:
        keys = {k: v for k, v in keys.items() if not k.startswith("joint_f.wear.")}
    # The wear regimes' keys at their defaults are the single k = 1e-7 a state written before them knew:
    # the same scene (its identity written as then).
    for table in ("joint_e", "joint_f"):
        at = f"{table}.wear."
        if all(keys.get(at + name, value) == value for name, value in REGIME_DEFAULTS.items()):
            for name in REGIME_DEFAULTS:
                keys.pop(at + name, None)
            if keys.get(at + "wear_coefficient", 0.0) is None:
                keys[at + "wear_coefficient"] = REGIME_DEFAULTS["boundary_wear_coefficient"]
    for name, value in DUTY_DEFAULTS.items():  # the steady prediction's duty keys, which a state before them lacks
        if keys.get("duty." + name) == value:
            keys.pop("duty." + name)
    for table, joint in (("joint_e", scene.joint), ("joint_f", scene.joint_f)):
        if joint.lubrication is None or not joint.lubrication.has_oil:  # the oil's keys change nothing without one
            keys = {k: v for k, v in keys.items() if k not in {f"{table}.lubrication.{name}" for name in HEAT_KEYS}}
    for attribute in ("rapier_tape", "exchange"):  # no tape / no exchange: their keys (all unset) change nothing
        if getattr(scene, attribute) is None:
            keys = {k: v for k, v in keys.items() if not k.startswith(attribute + ".")}
    for table in ("joint_e", "joint_f"):  # unset (None): only the cylindrical law reads it, and it refuses None
        if keys.get(f"{table}.bushing_wall_mm", 0.0) is None:
            keys.pop(f"{table}.bushing_wall_mm")
    for table in ("joint_e", "joint_f"):  # the steady elastic film's keys at their defaults, for a state before them
        for name, default in ELASTIC_DEFAULTS.items():
            if keys.get(f"{table}.lubrication.{name}", default) in (default, None):  # None: a dry joint's
                keys.pop(f"{table}.lubrication.{name}", None)
    return json.dumps(keys, sort_keys=True, default=str)


# The keys of the steady elastic film (weftsim.joint.ehl) and the asperities' own modulus, at the values that change
# nothing (weftsim.input.params.Lubrication's defaults; unset on a dry joint): a wear state written before them is
# the same scene's.
ELASTIC_DEFAULTS: dict[str, object] = {"elastic_film": False, "summit_height_um": 0.0, "pressure_viscosity_per_gpa": 0.0,
                    "asperity_modulus_gpa": 0.0, "surface_roughness_um": None, "peklenik_numbers": None}


DUTY_DEFAULTS = {"stops_per_hour": 0.0, "stop_minutes": 2.87, "hours_per_day": 24.0, "days_per_week": 7.0,
                 "startup_revolutions": 1.0, "rundown_revolutions": 1.0}  # weftsim.input.params.Duty's
REGIME_DEFAULTS = {"regime": "boundary", "dry_wear_coefficient": 5e-3, "boundary_wear_coefficient": 1e-7,
                   "mixed_wear_coefficient": 1e-7, "run_in_roughness_um": None, "run_in_depth_um": 1.0}  # weftsim.input.params.WearModel's defaults
