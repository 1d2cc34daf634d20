"""The keys of the two clearance joints as a scene gives them: what joint F takes from joint E, and
keys that describe a joint which is ideal in the scene (and so would change nothing).

Joint F (rod 4 - sector 5) is ideal unless a scene gives ``joint_f.clearance_mm > 0``.  Given a
clearance on its own, F takes every other key of ``[joint_e]`` (pin, bearing, law, restitution,
friction, materials, the wear table) unless the scene or the command line gives it for F:
:func:`inherit_joint_f`.  The scene remembers which keys F took (``Scene.joint_f_inherits``), so an
override of E's pin in a sweep cell moves F's pin with it (:func:`resync_joint_f`).

A key of a joint table other than its ``clearance_mm`` describes the clearance joint: on an ideal
joint it does nothing.  Set on the command line (``--set``, ``--vary``, a shorthand) or through the
Python overrides it is refused (:func:`ideal_joint_keys`, :func:`ideal_key_message`), so that
``run --set`` and ``sweep --vary`` of the same key say the same thing instead of one refusing and
the other making identical cells.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from weftsim.errors import SceneError
from weftsim.input.schema import _BY_PATH, SCHEMA, _set, shown

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# Table -> (joint letter, Scene attribute).
JOINTS = {"joint_e": ("E", "joint"), "joint_f": ("F", "joint_f")}
# The keys that name a joint's lubricant (a fixed viscosity, or an oil): F takes them from E together or not at all.
LUBRICANT = ("lubrication.viscosity_mpa_s", "lubrication.oil", "lubrication.oil.nu40_mm2_s",
             "lubrication.oil.nu100_mm2_s")
CLEARANCE = "clearance_mm"


def joint_table(path: str) -> str | None:
    """``"joint_e"`` or ``"joint_f"`` for a key of a joint table (``joint_f.law``), else None."""
    table = path.partition(".")[0]
    return table if table in JOINTS and "." in path else None


def describes_joint(path: str) -> bool:
    """True for a key of a joint table that describes the clearance joint (all but ``clearance_mm``)."""
    return joint_table(path) is not None and path.partition(".")[2] != CLEARANCE


def _f_keys() -> tuple[str, ...]:
    """The keys of [joint_f] without the table name, except ``clearance_mm``, in schema order."""
    return tuple(key.path.partition(".")[2] for key in SCHEMA
                 if key.path.startswith("joint_f.") and key.path != "joint_f." + CLEARANCE)


def inherit_joint_f(flat: dict[str, Any]) -> tuple[dict[str, Any], tuple[str, ...]]:
    """``flat`` (dotted file keys) with each [joint_f] key it lacks taken from [joint_e], and the names taken.

    Only keys [joint_e] gives are taken (an optional key neither gives keeps its default at both joints).
    A [joint_f] that gives keys but no ``clearance_mm`` is left as it is: :func:`ideal_joint_keys` refuses it.
    """
    out = dict(flat)
    taken = []
    own_lubricant = any("joint_f." + rest in out for rest in LUBRICANT)
    for rest in _f_keys():
        mine, hers = "joint_f." + rest, "joint_e." + rest
        if own_lubricant and rest in LUBRICANT:
            continue  # F names its own lubricant (a viscosity or an oil): E's other one is not F's
        if mine not in out and hers in out:
            out[mine] = out[hers]
            taken.append(rest)
    return out, tuple(taken)


def _value(scene: Scene, target: str) -> Any:
    obj: Any = scene
    for part in target.split("."):
        obj = getattr(obj, part)
    return obj


def resync_joint_f(scene: Scene, overridden: set[str] | dict) -> Scene:
    """``scene`` after overrides: the keys F takes from E follow E again, except those now given for F.

    ``overridden``: the dotted keys just applied.  A key given for F stops being taken from E.
    """
    inherits = tuple(rest for rest in scene.joint_f_inherits if "joint_f." + rest not in overridden)
    if any(rest in LUBRICANT for rest in inherits):  # F's lubricant is E's: all of it (a viscosity or an oil)
        inherits = tuple(rest for rest in inherits if rest not in LUBRICANT) + LUBRICANT
    if any(str(key).startswith("joint_e.") for key in overridden):
        for rest in inherits:
            if rest not in LUBRICANT:
                scene = _set(scene, _BY_PATH["joint_f." + rest].target,
                             _value(scene, _BY_PATH["joint_e." + rest].target))
        if LUBRICANT[0] in inherits and scene.joint_f.lubrication is not None:
            scene = _lubricant_of_e(scene)
    return replace(scene, joint_f_inherits=inherits)


def _lubricant_of_e(scene: Scene) -> Scene:
    """``scene`` with joint F's lubricant (fixed viscosity or oil) set to E's, in one step (no state naming both)."""
    e, f = scene.joint.lubrication, scene.joint_f.lubrication
    if e is None or f is None:  # resync_joint_f calls this only when F has a film and takes E's (then E has one)
        raise SceneError("joint F takes its lubricant from joint E, but joint "
                         f"{'E' if e is None else 'F'} has no [lubrication] table (a dry joint)")
    lub = replace(f, viscosity=e.viscosity if not e.has_oil else 0.0, oil=e.oil, oil_nu40=e.oil_nu40,
                  oil_nu100=e.oil_nu100, film_temperature=None)
    return replace(scene, joint_f=replace(scene.joint_f, lubrication=lub))


def ideal_joint_keys(scene: Scene, keys) -> list[str]:
    """The keys among ``keys`` that describe a joint which is ideal in ``scene`` (they change nothing)."""
    out = []
    for key in keys:
        table = joint_table(key)
        if table is not None and describes_joint(key) and getattr(scene, JOINTS[table][1]).is_ideal:
            out.append(key)
    return out


def ideal_key_message(key: str, where: str = "command line") -> str:
    """The one line refusing ``key`` on an ideal joint, the same for ``run --set``, ``--vary`` and the API."""
    table = joint_table(key)
    if table is None:
        raise ValueError(f"ideal_key_message: '{key}' is not a key of a joint table (one of {sorted(JOINTS)})")
    letter = JOINTS[table][0]
    return (f"{where}: key '{shown(key)}' describes the clearance joint at {letter}, but joint {letter} is ideal "
            f"in this scene ({table}.{CLEARANCE} = 0 or not given), so it would change nothing; give "
            f"{table}.{CLEARANCE} > 0 as well (e.g. --set {table}.{CLEARANCE}=0.25) or leave the key out")


def wear_only_keys(keys) -> list[str]:
    """The keys among ``keys`` of a ``[joint_*.wear]`` table: read by ``weftsim wear`` alone."""
    return [key for key in keys if ".wear." in str(key) and joint_table(str(key)) is not None]


def wear_only_message(key: str, command: str) -> str:
    """The one line refusing a wear key where it would change nothing (any command but ``weftsim wear``)."""
    return (f"key '{shown(key)}' is read by `weftsim wear` only: `weftsim {command}` does not depend on it, so it "
            "would change nothing (every cell of a sweep would be the same run); leave it out or run `weftsim wear`")


def inheritance_note(scene: Scene) -> str | None:
    """One line saying which keys joint F took from joint E, when F has a clearance and took any; else None."""
    if scene.joint_f.is_ideal or not scene.joint_f_inherits:
        return None
    names = scene.joint_f_inherits
    listed = ", ".join(names) if len(names) <= 4 else f"{', '.join(names[:4])} and {len(names) - 4} more"
    what = "pin, law, materials and wear keys" if any(n.startswith("wear.") for n in names) else "pin, law and materials"
    return (f"joint F (clearance {scene.joint_f.clearance * 1e3:g} mm) takes the {what} of "
            f"joint E where [joint_f] does not give them: {listed}; set joint_f.<key> to differ")
