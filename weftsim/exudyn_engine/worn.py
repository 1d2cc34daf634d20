"""A run of the kinematic tree on a worn joint E, with its step rows: what ``weftsim wear --engine exudyn`` simulates.

The worn geometry reaches the tree's contact through the scene (``joint.bearing_wear``,
``joint.journal_wear``): :func:`weftsim.model.dynamics.pack_parameters` appends the wear block,
and :func:`weftsim.physics.chain.tree_joint_force` reads the local clearance c0 + h_b + h_j along e
from it (:func:`weftsim.physics.chain.clearance_along`), as the reference engine's chain does.

:data:`ATTEMPTS`: a run that fails (a hard cycle) is tried again at a tighter relative tolerance, then
on the implicit tree (generalized-alpha with error control), as the reference engine's update is
tried at tighter tolerances and then on its implicit method.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from weftsim.exudyn_engine.selection import tree_relative_tolerance

if TYPE_CHECKING:
    from weftsim.input.params import Scene

# Relative tolerance of the explicit tree on a worn geometry, and of its retry.  The default 1e-6 is the
# tree's own (the engines' compare meets its tolerances there); a failed update is run again at 1e-8.
RETRY_RELATIVE_TOLERANCE = 1e-8
# (tree_solver, relative tolerance at most) of each attempt; None keeps the scene's.
ATTEMPTS = (("auto", None), ("explicit", RETRY_RELATIVE_TOLERANCE), ("implicit", None))


def attempt_scene(scene: Scene, attempt: int) -> Scene:
    """``scene`` on the kinematic tree with the solver of attempt ``attempt`` (:data:`ATTEMPTS`)."""
    solver, rtol = ATTEMPTS[attempt]
    s = scene.exudyn_solver
    s = replace(s, model="kinematic_tree", tree_solver=solver if solver != "auto" else s.tree_solver)
    if rtol is not None:
        s = replace(s, relative_tolerance=min(s.relative_tolerance, rtol))
    return replace(scene, exudyn_solver=s)
