"""Which Exudyn model and method a scene runs on (``RunResult.path``): the automatic selection.

``solver.exudyn.model = "auto"`` (the default) picks the smallest model that carries the scene:

- **kinematic tree** (:mod:`.tree`, :mod:`.tree_solve`) when members 1-3 are ideal and rigid and
  the clearance joint at E is the only free joint.  Then the crank, coupler and rocker move in
  closed form with the crank angle, and only the two coordinates of the chain 4-8 behind the
  clearance are integrated, by an explicit error-controlled solver (DOPRI5) that takes large steps
  in free flight and short ones through the impacts; with friction in the joint by generalized-alpha
  with an error-controlled step (``solver.exudyn.tree_solver``,
  :func:`weftsim.exudyn_engine.tree_solve.tree_solver`): the friction ramp holds an explicit solver
  at ~1e-9 s steps while the journal creeps.  Every scene weftsim describes today with a
  clearance at E is of this kind.
- **rigid-body model** (:mod:`.mechanism`, generalized-alpha) when the scene needs bodies and joints
  for members 1-3.  What forces it (:func:`rigid_body_needs`):
  an ideal joint at E (c = 0: no coordinate moves freely; the rigid-body model then steps
  0.25 deg of crank, :data:`weftsim.exudyn_engine.solver.IDEAL_JOINT_STEP_ANGLE`, and never a
  contact time scale).  Friction in the clearance joint does not: the tree's generalized force
  carries the friction force at the contact point and its moments on the rod and, through the
  driving torque, on the rocker (:func:`weftsim.kernel.chain.tree_joint_force`).  A clearance or a
  flexible body anywhere in members 1-3 would need the rigid-body model (members 1-3 no longer move
  in closed form); weftsim's scenes have neither yet.

``"rigid_body"`` and ``"kinematic_tree"`` stay explicit choices.  :func:`weftsim.exudyn_engine.solve`
runs exactly the model this module names.
"""

from __future__ import annotations

from weftsim.params import Scene

AUTO = "auto"


def rigid_body_needs(scene: Scene) -> list[str]:
    """Reasons why ``scene`` needs the rigid-body model (empty: the kinematic tree carries it)."""
    needs = []
    if not scene.joint_f.is_ideal:
        needs.append("clearance at F (the kinematic tree carries the clearance at E only; the rigid-body "
                     "model adds the reusable clearance joint at F)")  # fmt: skip
    if scene.is_ideal:
        needs.append("ideal joint at E (c = 0): no free coordinate, one generalized-alpha step per "
                     "0.25 deg of crank")  # fmt: skip
    return needs


def select_model(scene: Scene) -> tuple[str, str]:
    """(model, reason): the scene key if it names a model, else the automatic choice."""
    model = scene.exudyn_solver.model
    if model != AUTO:
        return model, "scene key solver.exudyn.model"
    needs = rigid_body_needs(scene)
    if needs:
        return "rigid_body", "auto: " + "; ".join(needs)
    return "kinematic_tree", "auto: members 1-3 ideal and rigid, only the chain 4-8 behind the clearance moves freely"


def select_path(scene: Scene) -> dict:
    """``{"model", "method", "reason"}`` of the run :func:`weftsim.exudyn_engine.solve` makes of ``scene``."""
    s = scene.exudyn_solver
    model, reason = select_model(scene)
    if model == "kinematic_tree":
        from weftsim.exudyn_engine.callbacks import resolve_route
        from weftsim.exudyn_engine.tree_solve import tree_local_error, tree_relative_tolerance, tree_solver

        route = resolve_route(s.callback)
        if tree_solver(scene) == "implicit":
            return {"model": model, "reason": reason,
                    "method": f"generalized-alpha, adaptive step (local error {tree_local_error(scene):g} m at E), "
                              f"{route} callback"}
        return {"model": model, "reason": reason,
                "method": f"{s.explicit_method} rtol {tree_relative_tolerance(scene):g}, {route} callback"}
    from weftsim.exudyn_engine.solver import adaptive, step_plan

    if adaptive(scene):
        where = " and ".join(name.upper() for name in scene.loose_joints)  # the rod's pins with a clearance
        method = f"generalized-alpha, adaptive step (local error {s.local_error:g} m at {where})"
    else:
        method = f"generalized-alpha, fixed step h {step_plan(scene)[0]:.3g} s"
    return {"model": model, "method": method, "reason": reason}
