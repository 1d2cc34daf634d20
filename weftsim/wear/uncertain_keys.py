"""Which scene keys a wear ensemble may take as uncertain: those that change the wear of the scene's joint E.

An ``--uncertain KEY=DISTRIBUTION`` is a machine's input whose spread spreads the hours to a clearance
limit.  A key is refused (one line, :func:`uncertain_key_problem`) when its distribution could not do that,
or would change what is modelled instead of a value of it:

- it is not a number (``joint_e.law``, ``solver.exudyn.model``, ``name``): a distribution draws numbers;
  a whole-number key (``joint_e.wear.profile_points``) is a setting, not a measured value;
- it has no physics (``output.*``, ``compare.*``, ``limits.*``, ``solver.*``, a material's
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
- it is joint E's ``clearance_mm`` while E is ideal (there would be no contact to wear).

Every other key (geometry, inertia, speed, the joint's pin, materials, friction, restitution, film
values of a lubricated joint, k and the hardnesses) enters the dynamics or Archard's law: it may be
uncertain.  The names are those ``--set`` takes: a dotted key, or its last part where that is unique
(:func:`weftsim.sweep.grid.resolve_key`).
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


def resolve(name: str) -> str:
    """The dotted scene key of ``name`` (a dotted key or the short name ``--set`` takes); WearError otherwise."""
    from weftsim.errors import SweepError
    from weftsim.sweep.grid import resolve_key

    try:
        return resolve_key(name).path
    except SweepError as exc:
        text = str(exc).replace("sweep key", "key")
        raise WearError(f"--uncertain {name}: {text}") from None


def uncertain_key_problem(key: str, scene: Scene) -> str | None:
    """Why ``key`` (dotted) cannot be an uncertain input of a wear ensemble of ``scene``, or None if it can."""
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
    return None


def check_uncertain_key(name: str, scene: Scene) -> str:
    """The dotted key of ``name`` if it may be uncertain in an ensemble of ``scene``; WearError (one line) if not."""
    key = resolve(name)
    problem = uncertain_key_problem(key, scene)
    if problem is not None:
        raise WearError(f"--uncertain {key}: {problem}; an uncertain key must change the wear of joint E "
                        "(the geometry, inertia, speed, the joint's pin, materials, friction or film values, k or "
                        "a hardness: docs/wear.md section 9)")
    return key
