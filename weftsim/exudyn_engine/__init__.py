"""Exudyn engine of weftsim: the only package that imports ``exudyn``.

Public API::

    solve(scene, progress=None) -> weftsim.post.results.RunResult
    select_path(scene) -> dict                                 the model and method solve will use, and why
    build_mechanism(mbs, scene, ...) -> MechanismModel          members 1-8 in an Exudyn system
    add_clearance_joint(mbs, marker_bearing, marker_journal, joint, law=None, callback="auto")
        -> ClearanceJointModel                                   reusable planar clearance joint

See docs/clearance-joint.md.
"""

from weftsim.exudyn_engine.clearance_joint import (
    DEFAULT_ROUTE,
    ROUTES,
    ClearanceJointModel,
    add_clearance_joint,
    register_post_step,
)
from weftsim.exudyn_engine.mechanism import MechanismModel, build_mechanism
from weftsim.exudyn_engine.selection import select_path
from weftsim.exudyn_engine.solver import solve

__all__ = [
    "solve",
    "select_path",
    "build_mechanism",
    "MechanismModel",
    "add_clearance_joint",
    "ClearanceJointModel",
    "register_post_step",
    "ROUTES",
    "DEFAULT_ROUTE",
]
