"""The channels a run reports, shared by both engines: their names (units in the names) and groups.

Every engine fills :data:`CHANNELS`; the optional groups (joint F's, a lubricated joint's, the load a loose
joint carries, the flexible tape's) are present exactly when the scene has what they describe
(:func:`optional_channels`).  The names live here, below the joint and the engines, so the modules that compute
a channel and :class:`weftsim.post.results.RunResult` that holds it name it from one place.
"""

from __future__ import annotations

CHANNELS: tuple[str, ...] = (
    "time_s",
    "crank_angle_deg",
    "rapier_displacement_m",
    "rapier_velocity_m_s",
    "rapier_acceleration_m_s2",
    "driving_torque_Nm",
    "contact_force_N",
    "penetration_m",
    "eccentricity_y_m",
    "eccentricity_z_m",
    "impact_velocity_m_s",
    "in_contact",
    "kinetic_energy_J",
    "potential_energy_J",
    "contact_energy_J",
    "driving_work_J",
    "dissipated_energy_J",
    "penetration_rate_m_s",
)

# Channels of joint F (rod 4 - sector 5), present exactly when the scene gives F a clearance
# (docs/clearance-f.md); the unsuffixed contact channels above are joint E's (their names predate F).
# The energy channels are the mechanism's: contact_energy_J and dissipated_energy_J hold both joints.
JOINT_F_CHANNELS: tuple[str, ...] = (
    "contact_force_f_N",
    "penetration_f_m",
    "eccentricity_f_y_m",
    "eccentricity_f_z_m",
    "impact_velocity_f_m_s",
    "in_contact_f",
    "penetration_rate_f_m_s",
)

# Channels of a lubricated joint (docs/lubricated-joint.md), present exactly when the scene gives the joint a
# [joint_e.lubrication] / [joint_f.lubrication] table: minimum film thickness h_min = max(c - |e|, 0), film
# ratio h_min / sigma, the film force's magnitude, the asperity load, the film's shear torque on the journal.
LUBRICATION_CHANNELS: tuple[str, ...] = (
    "film_thickness_m",
    "film_ratio",
    "film_force_N",
    "asperity_force_N",
    "film_torque_Nm",
)
LUBRICATION_CHANNELS_F: tuple[str, ...] = (
    "film_thickness_f_m",
    "film_ratio_f",
    "film_force_f_N",
    "asperity_force_f_N",
    "film_torque_f_Nm",
)

# The load a loose joint carries (film + asperities + dry law, weftsim.joint.load), present for every loose joint
# E / F (results saved before it existed lack it: weftsim.joint.load.joint_load reads their contact force).
JOINT_FORCE_CHANNELS: tuple[str, ...] = ("joint_force_N",)
JOINT_FORCE_CHANNELS_F: tuple[str, ...] = ("joint_force_f_N",)
# What a result saved before the load channels existed gives in their place: its dry law's contact force.
LOAD_FALLBACK = {"joint_force_N": "contact_force_N", "joint_force_f_N": "contact_force_f_N"}
# Channels of the flexible rapier tape (docs/rapier-tape.md), present exactly when the run models the tape as
# flexible (weftsim.model.tape_selection.tape_model): the head's motion (s of the head's rigid position plus the tape's
# axial displacement there), the tape's axial force where it leaves the wheel and at the head (tension
# positive), the free length, its first axial natural frequency (the closed form at that length) and the
# tape's strain energy.  rapier_* stay the wheel's pitch-circle motion (the rigid rapier's).
TAPE_CHANNELS: tuple[str, ...] = (
    "head_displacement_m",
    "head_velocity_m_s",
    "head_acceleration_m_s2",
    "tape_force_wheel_N",
    "tape_force_head_N",
    "tape_free_length_m",
    "tape_frequency_hz",
    "tape_strain_energy_J",
)

# Channels of the weft exchange (weftsim.model.exchange, docs/rapier-tape.md section 7), present exactly when the
# scene has an [exchange] that is on: the taker head's position and velocity into the shed from its side, the
# heads' overlap (how far they have passed each other) and relative speed, and each head's position error against
# the ideal rigid mechanism.  The giver's head is head_displacement_m (flexible tape) or rapier_displacement_m.
EXCHANGE_CHANNELS: tuple[str, ...] = (
    "taker_head_displacement_m",
    "taker_head_velocity_m_s",
    "exchange_overlap_m",
    "exchange_relative_speed_m_s",
    "giver_head_error_m",
    "taker_head_error_m",
)

# Joint E's channel of each joint-F channel (same quantity at the other joint).
JOINT_E_NAME = dict(zip(JOINT_F_CHANNELS, ("contact_force_N", "penetration_m", "eccentricity_y_m",
                                           "eccentricity_z_m", "impact_velocity_m_s", "in_contact",
                                           "penetration_rate_m_s")))

# Channels that describe the contact at E; identically zero for the ideal joint.
CONTACT_CHANNELS: tuple[str, ...] = (
    "contact_force_N",
    "penetration_m",
    "eccentricity_y_m",
    "eccentricity_z_m",
    "impact_velocity_m_s",
    "in_contact",
    "contact_energy_J",
    "dissipated_energy_J",
    "penetration_rate_m_s",
)

# Channels summarised by peaks and statistics (docs/physics.md section 4; paper Fig. 12).
PEAK_CHANNELS: tuple[str, ...] = (
    "rapier_displacement_m",
    "rapier_velocity_m_s",
    "rapier_acceleration_m_s2",
    "driving_torque_Nm",
    "contact_force_N",
    "penetration_m",
)
# Joint F's peak channels (summaries of a scene with clearance at F).
PEAK_CHANNELS_F: tuple[str, ...] = ("contact_force_f_N", "penetration_f_m")
# Peak channels of a lubricated joint (E's, F's); the film ratio's minimum is its summary (analysis).
PEAK_CHANNELS_LUBRICATION: tuple[str, ...] = ("film_force_N", "asperity_force_N", "film_torque_Nm")
PEAK_CHANNELS_LUBRICATION_F: tuple[str, ...] = ("film_force_f_N", "asperity_force_f_N", "film_torque_f_Nm")
# Peak channels of the flexible rapier tape; the first frequency's min and max span the stroke.
PEAK_CHANNELS_TAPE: tuple[str, ...] = ("head_displacement_m", "head_velocity_m_s", "head_acceleration_m_s2",
                                       "tape_force_wheel_N", "tape_force_head_N", "tape_frequency_hz")


OPTIONAL_GROUPS = (JOINT_F_CHANNELS, LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F, JOINT_FORCE_CHANNELS,
                   JOINT_FORCE_CHANNELS_F, TAPE_CHANNELS, EXCHANGE_CHANNELS)


def optional_channels(names) -> tuple[str, ...]:
    """The optional channel groups (joint F's, the lubricated joints') present among ``names``, in order."""
    present = set(names)
    out: tuple[str, ...] = ()
    for group in OPTIONAL_GROUPS:
        if group[0] in present:
            out += group
    return out
