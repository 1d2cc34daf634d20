"""``weftsim bearing``: the steady plain-bearing check of a lubricated joint, and its film temperature for a run.

The calculation a designer makes first (ISO 7902-1 / DIN 31652's steps, on the joint's own kernel): the
ideal mechanism's loads on the pin (:func:`weftsim.mechanism.pin_loads.ideal_pin_loads`) give two steady
operating points, the **mean** load at the mean sliding speed and the **peak** load at the same speed; at each
the journal is a steadily loaded bearing (:mod:`weftsim.joint.steady`), with the film at the mean point's
effective temperature (:mod:`weftsim.joint.heat`, when the scene names an oil: the peak lasts a fraction of a
cycle, too short to heat the film) or at the scene's fixed viscosity.  The
relative sliding speed v = R_j abs(omega_rel) becomes a journal speed omega = v / R_j in a still bushing.
``load`` and ``journal_rpm`` evaluate any other operating point instead (the bearing alone).  The Stribeck
curve is the friction coefficient of the same bearing against journal speed at the point's load, each speed
at its own film temperature.

The transient engines take the oil's viscosity at the mean point's effective temperature
(:func:`resolve_scene`, before the run): the film's temperature follows the cycle's mean heat, not its
instants (the heat capacity of pin and bushing averages a cycle of 0.1 s).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import SceneError

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# The Stribeck curve: journal speeds from 1e-3 to 10 x the operating point's, log-spaced.
STRIBECK_POINTS, STRIBECK_SPAN = 41, (1e-3, 10.0)


def _joint(scene, name: str):
    return scene.joint if name == "e" else scene.joint_f


def _table(name: str) -> str:
    return f"joint_{name}"


def check_bearing_joint(scene, name: str) -> None:
    """Refuse, in one line, a joint the bearing check cannot judge: ideal, dry, or oiled with no oil."""
    if name not in ("e", "f"):
        raise SceneError(f"bearing: joint must be 'e' or 'f', got {name!r}")
    joint, table = _joint(scene, name), _table(name)
    if joint.is_ideal:
        raise SceneError(f"bearing: joint {name.upper()} is ideal in this scene ({table}.clearance_mm = 0 or not "
                         f"given): a plain bearing needs a clearance; give {table}.clearance_mm > 0")
    lub = joint.lubrication
    if lub is None or (not lub.has_oil and lub.viscosity <= 0.0):
        raise SceneError(f"bearing: joint {name.upper()} is dry (no oil): give {table}.lubrication.oil (e.g. "
                         f"--set \"{table}.lubrication.oil=ISO VG 220\") or {table}.lubrication.viscosity_mpa_s > 0")


def mean_operating_point(scene, name: str) -> tuple[float, float, float]:
    """(mean load N, peak load N, journal speed rad/s) of the ideal mechanism at joint ``name`` (mean sliding
    speed over the pin radius)."""
    from weftsim.mechanism.pin_loads import ideal_pin_loads

    loads = ideal_pin_loads(scene, name)
    return float(loads.force.mean()), float(loads.force.max()), float(loads.sliding_speed.mean()) / _joint(
        scene, name).journal_radius


def operating_point(joint, load: float, omega: float, film: dict | None = None, warm: dict | None = None) -> dict:
    """One steady point as a dict: the :class:`~weftsim.joint.steady.SteadyPoint` numbers, and the heat balance
    (``heat``; None for a fixed viscosity, or when ``film``, another point's dict, gives the film's temperature).
    ``warm``: the elastic film's start kept between neighbouring points (:func:`weftsim.joint.ehl.elastic_point`)."""
    from weftsim.joint.heat import heat_balance
    from weftsim.joint.steady import steady_point

    lub = joint.lubrication
    if film is not None:
        point = steady_point(joint, load, omega, film["viscosity_pa_s"], warm=warm)
        return {**point.as_dict(), "film_temperature_c": film["film_temperature_c"], "heat": None}
    if lub.has_oil:
        balance = heat_balance(joint, load, omega, warm=warm)
        return {**balance.point.as_dict(), "film_temperature_c": balance.temperature_c, "heat": balance.as_dict()}
    return {**steady_point(joint, load, omega, lub.viscosity, warm=warm).as_dict(), "film_temperature_c": None,
            "heat": None}


def stribeck(joint, load: float, omega: float, points: int = STRIBECK_POINTS) -> dict:
    """The friction coefficient against journal speed at ``load``: speeds (rad/s) log-spaced over
    :data:`STRIBECK_SPAN` x ``omega``, each with its film temperature, film ratio and regime (``"overheats"``, and
    NaN, where no temperature balances the friction power)."""
    speeds = omega * np.geomspace(*STRIBECK_SPAN, points)
    rows = []
    warm: dict = {}  # each speed's elastic film starts from the last one's (weftsim.joint.ehl.elastic_point)
    for w in speeds:
        try:
            rows.append(operating_point(joint, load, float(w), warm=warm))
        except SceneError:  # no heat balance at this speed: the bearing overheats there
            rows.append({"friction_coefficient": math.nan, "film_ratio": math.nan, "regime": "overheats",
                         "film_temperature_c": None})
    return {"journal_speed_rad_s": [float(w) for w in speeds],
            "friction_coefficient": [r["friction_coefficient"] for r in rows],
            "film_ratio": [r["film_ratio"] for r in rows], "regime": [r["regime"] for r in rows],
            "film_temperature_c": [r["film_temperature_c"] for r in rows]}


def bearing(scene, joint: str = "e", load: float | None = None, journal_rpm: float | None = None,
            curve: bool = True) -> dict:
    """The steady plain-bearing check of joint ``joint`` of ``scene`` (module docstring).

    ``load`` (N) and ``journal_rpm`` (journal speed, bushing still) give one operating point of their own
    (each defaults to the mechanism's mean); otherwise the mean and peak points of the ideal mechanism.
    ``curve``: add the Stribeck curve at the (first) point's load.  Refuses (:class:`SceneError`, one line) an
    ideal or dry joint and a negative or non-finite load or speed.
    """
    check_bearing_joint(scene, joint)
    for value, what in ((load, "load"), (journal_rpm, "journal speed")):
        if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
            raise SceneError(f"bearing: the {what} must be a finite number > 0, got {value!r}")
    part = _joint(scene, joint)
    lub = part.lubrication
    mean, peak, omega = mean_operating_point(scene, joint)
    if load is None and journal_rpm is None:
        points = {"mean": (mean, omega), "peak": (peak, omega)}
    else:
        points = {"given": (mean if load is None else float(load),
                            omega if journal_rpm is None else float(journal_rpm) * 2.0 * math.pi / 60.0)}
    out = {"scene": scene.name, "joint": joint.upper(), "oil": lub.oil_model.name if lub.has_oil else None,
           "viscosity_mpa_s": None if lub.has_oil else 1e3 * lub.viscosity,
           "ambient_temperature_c": lub.ambient_temperature if lub.has_oil else None,
           "clearance_mm": 1e3 * part.clearance, "journal_diameter_mm": 2e3 * part.journal_radius,
           "bearing_length_mm": 1e3 * part.bearing_length, "roughness_um": 1e6 * lub.roughness,
           "points": {}}
    for name, (w, o) in points.items():  # the peak's film is the mean's: a peak lasts too short to heat it
        film = out["points"].get("mean") if name == "peak" else None
        out["points"][name] = operating_point(part, w, o, film)
    out["notes"] = model_notes(lub, out["points"], joint)
    if curve:
        first_load, first_omega = next(iter(points.values()))
        out["stribeck"] = {"load_n": first_load, "operating_speed_rad_s": first_omega,
                           **stribeck(part, first_load, first_omega)}
    return out


# What the rigid film was measured to do below its full-film range (docs/lubricated-joint.md, "Stribeck data"):
# on Sander et al.'s rig it reads 0.23-0.61 of the published torque where the film is mixed, the elastic film with
# the source's surfaces 0.81-1.16 at every published point.
RIGID_MIXED_NOTE = ("{names}: mixed or boundary regime with the rigid film, whose friction there was measured at "
                    "0.23-0.61 of a published Stribeck test (docs/lubricated-joint.md, Stribeck data); "
                    "joint_{joint}.lubrication.elastic_film = true with the surfaces' keys (summit_height_um, "
                    "surface_roughness_um, peklenik_numbers) matched it within 0.81-1.16")


def model_notes(lub, points: dict, joint: str = "e") -> list[str]:
    """Lines saying where a point lies outside what its film model was shown to reproduce (empty: none)."""
    outside = [name for name, p in points.items() if p["regime"] != "hydrodynamic"]
    if outside and not lub.elastic_film:
        return [RIGID_MIXED_NOTE.format(names=", ".join(outside), joint=joint)]
    return []


def _balanced(part):
    """The joint whose heat balance sets the film temperature: a worn joint (``weftsim wear``'s update) at its
    effective clearance c0 + max h_b + max h_j, the round joint of that clearance (docs/wear.md section 12)."""
    if not part.is_worn:
        return part
    worn = max(part.bearing_wear, default=0.0) + max(part.journal_wear, default=0.0)
    return replace(part, clearance=part.clearance + worn, bearing_wear=(), journal_wear=())


def resolve_scene(scene: Scene) -> Scene:
    """``scene`` with each oiled joint's viscosity at its effective film temperature (the heat balance at the
    ideal mechanism's mean load and sliding speed, :func:`weftsim.joint.heat.with_film_temperature`); scenes
    without an oil are returned as they are."""
    from weftsim.joint.heat import with_film_temperature

    for name in scene.loose_joints:
        part = _joint(scene, name)
        lub = part.lubrication
        if lub is None or not lub.has_oil:
            continue
        if (lub.oil_nu40 > 0.0) != (lub.oil_nu100 > 0.0):
            raise SceneError(f"{_table(name)}.lubrication: a custom oil needs both oil.nu40_mm2_s and oil.nu100_mm2_s "
                             "(its kinematic viscosities at 40 and 100 C)")
        if lub.viscosity > 0.0 and lub.film_temperature is None:
            raise SceneError(f"{_table(name)}.lubrication: viscosity_mpa_s and oil are both given: give the oil (its "
                             "viscosity then follows from the film temperature) or a fixed viscosity_mpa_s, not both")
        mean, _, omega = mean_operating_point(scene, name)
        try:
            resolved, _ = with_film_temperature(_balanced(part), mean, omega)
        except SceneError as exc:
            raise SceneError(f"{_table(name)}.lubrication at the ideal mechanism's mean pin load {mean / 1e3:.4g} kN "
                             f"and sliding speed {omega * part.journal_radius:.3g} m/s: {exc}") from None
        # the joint as it was (a worn one keeps its profiles), its lubrication at the film temperature found
        scene = replace(scene, **{"joint" if name == "e" else "joint_f": replace(part, lubrication=resolved.lubrication)})
    return scene
