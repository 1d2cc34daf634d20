"""Which scene keys a wear ensemble may take as uncertain: those that change the wear of the scene's joint E.

An ``--uncertain KEY=DISTRIBUTION`` is a machine's input whose spread spreads the hours to a clearance
limit.  A key is refused (one line, :func:`uncertain_key_problem`) when its distribution could not do that,
or would change what is modelled instead of a value of it:

- it is not a number (``joint_e.law``, ``solver.exudyn.model``, ``name``): a distribution draws numbers;
  a whole-number key (``joint_e.wear.profile_points``) is a setting, not a measured value;
- it has no physics (``output.*``, ``compare.*``, ``limits.*``, ``solver.*``, ``exchange.*``, a material's
  ``yield_strength_mpa``, ``max_pressure_mpa``, ``max_pv_mpa_m_s``): it sets what is written, checked or how
  closely it is solved, not the machine;
- it is an inertia of members 1-3 (crank, coupler, rocker): driven at the crank's constant speed, their
  motion does not depend on it (it sets the driving torque alone);
- it is a setting of the prediction itself (``drive.revolutions``: each update simulates
  ``[joint_e.wear]`` ``settle_revolutions`` + ``revolutions_per_update``; ``max_clearance_change``: the
  update interval, converged by design, docs/wear.md section 3);
- it belongs to joint F (an ensemble wears E with F ideal: a key of the ideal F changes nothing, and its
  ``clearance_mm`` would make F loose, another model);
- it belongs to ``[joint_e.lubrication]`` while joint E is dry (a viscosity would make it lubricated:
  another model; give the table in the scene to make the oil's values uncertain);
- it is joint E's ``clearance_mm`` while E is ideal (there would be no contact to wear);
- it belongs to ``[rapier_tape]`` while the scene has none (a tape key would add the flexible tape: another
  model), or it is the rigid rapier's ``inertia.rapier_mass_kg`` while the scene has a tape (which replaces it);
- nothing of the scene reads it: ``bushing_wall_mm`` under a law other than ``cylindrical``; a regime's k the
  joint does not wear in (``dry_wear_coefficient`` in the boundary regime, ``mixed_wear_coefficient`` on a dry
  joint, any regime's k under a given ``wear_coefficient``); running-in on a dry joint, or its depth without
  ``run_in_roughness_um``; the oil's properties and the heat balance under a fixed ``viscosity_mpa_s``;
  the dry ``friction_coefficient`` of a joint in oil (its solids carry the boundary coefficient);
  a stop's ``stop_minutes``, ``startup_revolutions`` or ``rundown_revolutions`` on a loom that does not stop
  (``stops_per_hour = 0``, unless that is uncertain too);
- it would change the lubricant's model: a grade's ``oil.nu40_mm2_s`` / ``oil.nu100_mm2_s``, a fixed
  ``viscosity_mpa_s`` on a joint given an oil.

Every other key (geometry, inertia, speed, the joint's pin, materials, friction, restitution, film
values of a lubricated joint, k and the hardnesses, the stop-starts of the duty cycle) enters the dynamics or
Archard's law; ``duty.hours_per_day`` and ``days_per_week`` spread the calendar days to the limit (the life
report, docs/wear.md section 12): it may be uncertain.  The names are those ``--set`` takes: a dotted key, or
its last part where that is unique (:func:`weftsim.sweep.grid.resolve_key`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from weftsim.errors import WearError

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# Tables that hold no physics of the machine, and why (the refusal's clause).
NO_PHYSICS = {
    "output.": "it sets the output grid, not the machine",
    "compare.": "it sets the engines' agreement tolerances, not the machine",
    "limits.": "it sets a run's guard or warning threshold, not the machine",
    "solver.": "it sets how closely a run is solved, not the machine",
    "exchange.": "it sets the weft exchange's outputs (the taker head beside the giver's), not joint E's wear",
}
# Members 1-3 (crank, coupler, rocker) are driven at the crank's constant speed through ideal joints: their
# motion is the crank's, whatever their inertia, which sets the driving torque alone.  (Measured: the reference
# scene's contact force at E over half a revolution is identical to the bit with each of these 30 % larger.)
PRESCRIBED = ("inertia.crank_inertia_kg_m2", "inertia.coupler_mass_kg", "inertia.coupler_inertia_kg_m2",
              "inertia.rocker_mass_kg", "inertia.rocker_com_mm", "inertia.rocker_inertia_kg_m2")
# A material's design limits: the after-run checks compare against them; no force depends on them.
DESIGN_LIMITS = ("yield_strength_mpa", "max_pressure_mpa", "max_pv_mpa_m_s")
# Settings of the wear prediction itself (its numerics), not of the machine.
PREDICTION_SETTINGS = {
    "drive.revolutions": "each update simulates [joint_e.wear] settle_revolutions + revolutions_per_update "
                         "revolutions whatever drive.revolutions says, so it does not change the wear",
    "joint_e.wear.max_clearance_change": "it sets the update interval of the prediction (converged by design, "
                                         "docs/wear.md section 3), not the machine",
}
# Keys of the steady elastic film of `weftsim bearing` (weftsim.joint.ehl): a wear prediction runs the transient
# engines, which keep the rigid film and refuse elastic_film, so these change nothing there.
STEADY_ONLY = ("joint_e.lubrication.summit_height_um", "joint_e.lubrication.pressure_viscosity_per_gpa",
               "joint_e.lubrication.surface_roughness_um", "joint_e.lubrication.peklenik_numbers")


def resolve(name: str) -> str:
    """The dotted scene key of ``name`` (a dotted key or the short name ``--set`` takes); WearError otherwise."""
    from weftsim.errors import SweepError
    from weftsim.sweep.grid import resolve_key

    try:
        return resolve_key(name).path
    except SweepError as exc:
        text = str(exc).replace("sweep key", "key")
        raise WearError(f"--uncertain {name}: {text}") from None


def uncertain_key_problem(key: str, scene: Scene, others: tuple[str, ...] = ()) -> str | None:
    """Why ``key`` (dotted) cannot be an uncertain input of a wear ensemble of ``scene``, or None if it can
    (``others``: the ensemble's other uncertain keys, dotted)."""
    from weftsim.input.schema import _BY_PATH

    spec = _BY_PATH.get(key)
    if spec is None:
        return "not a numeric scene key"
    if spec.kind != "float":
        kind = {"int": "a whole-number setting", "str": "a name", "bool": "true or false"}.get(spec.kind,
                                                                                            "a list of numbers")
        return f"it is {kind}, and a distribution draws single real numbers"
    if key in PRESCRIBED:
        return ("members 1-3 (crank, coupler, rocker) move as the constant-speed crank drives them: their inertia "
                "sets the driving torque, not the motion at E or its wear")
    for prefix, why in NO_PHYSICS.items():
        if key.startswith(prefix):
            return why
    if key.endswith(DESIGN_LIMITS):
        return "it is a design limit the checks compare against; no force or wear depends on it"
    if key in PREDICTION_SETTINGS:
        return PREDICTION_SETTINGS[key]
    if key in STEADY_ONLY:
        return ("it is a key of the steady elastic film of `weftsim bearing` only; the wear runs' rigid film "
                "does not read it, so it does not change the wear")
    if key.startswith("joint_f."):
        if scene.joint_f.is_ideal:
            return ("joint F is ideal in this scene (an ensemble wears E with F ideal): "
                    + ("a clearance would make it loose, another model" if key == "joint_f.clearance_mm"
                       else "its keys change nothing"))
        return "an ensemble wears joint E with F ideal"
    if key.startswith("joint_e.lubrication.") and not scene.joint.is_lubricated:
        return ("joint E is dry in this scene: a lubrication key would make it lubricated, another model; give "
                "[joint_e.lubrication] in the scene to make the oil's values uncertain")
    if key == "joint_e.clearance_mm" and scene.joint.is_ideal:
        return "joint E is ideal in this scene: there is no contact to wear"
    if key.startswith("rapier_tape.") and scene.rapier_tape is None:
        return ("the scene has no [rapier_tape] (the rigid rapier of mass m8): a tape key would add the flexible tape, "
                "another model; give [rapier_tape] in the scene to make the tape's values uncertain")
    if key == "inertia.rapier_mass_kg" and scene.rapier_tape is not None:
        return ("the scene's rapier is its [rapier_tape] (the head's and the tape's masses): the rigid rapier's mass "
                "does not change the wear")
    if key.startswith("joint_e."):
        return _joint_e_problem(key, scene, others)
    if key.startswith("duty.") and key.rpartition(".")[2] in STOP_KEYS and not scene.duty.stops_per_hour > 0.0 \
            and "duty.stops_per_hour" not in others:
        return ("the loom of this scene does not stop ([duty] stops_per_hour = 0): a stop's length and its transients "
                "do not change the wear or the calendar time")
    return None


# The [duty] keys that describe one stop: they count only on a loom that stops (weftsim.wear.duty.with_stops,
# weftsim.input.params.Duty.calendar_days).
STOP_KEYS = ("stop_minutes", "startup_revolutions", "rundown_revolutions")
# The [joint_e.lubrication] keys of an oil and of its heat balance (weftsim.joint.heat): read only when the joint is
# given an oil, its viscosity following from the film temperature.
OIL_VISCOSITIES = ("oil.nu40_mm2_s", "oil.nu100_mm2_s")
HEAT_KEYS = OIL_VISCOSITIES + ("oil.density_kg_m3", "oil.heat_capacity_j_kg_k", "ambient_temperature_c",
                               "housing_heat_transfer_w_k")
REGIME_KEYS = {"dry_wear_coefficient": "dry", "boundary_wear_coefficient": "boundary",
               "mixed_wear_coefficient": "mixed"}


def _joint_e_problem(key: str, scene: Scene, others: tuple[str, ...]) -> str | None:
    """Why a ``joint_e.*`` key changes nothing of this scene's joint E (or its model), or None."""
    joint, name = scene.joint, key.partition(".")[2]
    wear, lub = joint.wear, joint.lubrication
    if name == "bushing_wall_mm" and joint.law != "cylindrical":
        return (f"only the cylindrical contact law reads the bushing's wall, and joint E's law is {joint.law!r}: it "
                "does not change the wear")
    regime = REGIME_KEYS.get(name.removeprefix("wear."))
    if regime is not None:
        if wear.wear_coefficient is not None and "joint_e.wear.wear_coefficient" not in others:
            return ("joint E's wear_coefficient is given and is the k of every load, the regime's k does not change "
                    "the wear")
        if regime == "mixed" and not joint.is_lubricated:
            return ("mixed_wear_coefficient is the k of an oil film's asperity load, and joint E is dry: it does not "
                    "change the wear")
        if regime != "mixed" and wear.regime != regime:
            return (f"joint E's solid contact wears in the {wear.regime!r} regime ([joint_e.wear] regime): the "
                    f"{regime} k does not change the wear")
    if name == "friction_coefficient" and joint.is_lubricated:
        return ("joint E runs in oil, whose solids' contact carries the lubrication's boundary_friction_coefficient: "
                "the dry joint's friction coefficient is not read and does not change the wear; make "
                "joint_e.lubrication.boundary_friction_coefficient uncertain instead")
    if name in ("wear.run_in_roughness_um", "wear.run_in_depth_um") and not joint.is_lubricated:
        return "running-in lowers an oil film's roughness, and joint E is dry: it does not change the wear"
    if name == "wear.run_in_depth_um" and wear.run_in_roughness is None \
            and "joint_e.wear.run_in_roughness_um" not in others:
        return ("joint E has no run_in_roughness_um: its roughness does not run in, so the depth of running-in does "
                "not change the wear")
    if lub is not None and name.startswith("lubrication."):
        field = name.partition(".")[2]
        if field in OIL_VISCOSITIES and lub.oil:
            return (f"joint E's oil is the grade {lub.oil!r}, whose viscosities are the grade's: a custom oil would be "
                    "another model; give the custom oil (nu40_mm2_s and nu100_mm2_s) in the scene to make them "
                    "uncertain")
        if field in HEAT_KEYS and not lub.has_oil:
            return ("joint E's film has a fixed viscosity_mpa_s, not an oil: the oil's properties and the heat balance "
                    "do not change the wear; name the oil in the scene to make them uncertain")
        if field == "viscosity_mpa_s" and lub.has_oil:
            return ("joint E is given an oil, whose viscosity follows from the film temperature: a fixed viscosity "
                    "would be another model; make the oil's values uncertain instead")
    return None


def check_uncertain_key(name: str, scene: Scene, others: tuple[str, ...] = ()) -> str:
    """The dotted key of ``name`` if it may be uncertain in an ensemble of ``scene``; WearError (one line) if not.

    ``others``: the names of the ensemble's other uncertain keys (a stop's keys count when ``stops_per_hour``
    is uncertain, a regime's k when ``wear_coefficient`` is, the running-in depth when its roughness is)."""
    key = resolve(name)
    problem = uncertain_key_problem(key, scene, tuple(resolve(o) for o in others))
    if problem is not None:
        raise WearError(f"--uncertain {key}: {problem}; an uncertain key must change the wear of joint E "
                        "(the geometry, inertia, speed, the joint's pin, materials, friction or film values, k or "
                        "a hardness, the duty cycle: docs/wear.md sections 9 and 12)")
    return key
