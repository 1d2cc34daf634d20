"""Which joint laws of a scene are stiff for an explicit integrator (both engines' path choice and estimates)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from weftsim.input.params import Scene


def stiff_joints(scene: Scene) -> list[str]:
    """Why the scene's contact is stiff for an explicit method: one phrase per loose joint with friction
    (the modified Coulomb ramp) or a lubricating film (``lubrication`` of the joint, when the scene has one)."""
    out = []
    for name, joint in (("E", scene.joint), ("F", scene.joint_f)):
        if joint.is_ideal:
            continue
        if joint.friction_coefficient > 0.0:
            out.append(f"friction at {name} (mu = {joint.friction_coefficient:g})")
        if getattr(joint, "lubrication", None) is not None:  # hook for the lubricated joint
            out.append(f"oil film at {name}")
    return out
