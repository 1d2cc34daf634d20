"""A planar revolute clearance joint for any Exudyn mechanism (docs/physics.md sections 2-3).

:func:`add_clearance_joint` puts the joint between a bearing marker and a journal marker
(``MarkerBodyPosition`` at the two joint centres, bodies moving in Exudyn's XY plane,
joint axis = Exudyn Z) as an ``ObjectConnectorCartesianSpringDamper`` whose force callback
applies a contact law of :mod:`weftsim.joint.contact`.  The impact velocity is located at the
true onset within the step and held until separation, raised to any larger approach rate
under the default ``joint.impact_velocity_rule = "max_approach"`` (:mod:`.onset`); the
bookkeeping runs in a post-step user function, i.e. on accepted steps only.  Usage::

    model = add_clearance_joint(mbs, marker_bearing, marker_journal, joint)
    mbs.Assemble()
    model.reset(mbs)            # only if the journal does not start centred
    mbs.SolveDynamic(settings)
    model.tracker.history()     # time, held impact velocity, contact flag per step

Friction (``joint.friction_coefficient > 0``, :mod:`.joint_friction`): the connector's force
then includes the friction force, and a torque load on each rotating body carries its friction
moment about its centre; solve with ``timeIntegration.computeLoadsJacobian = 2`` and full Newton
(``newton.useModifiedNewton = False``) so that Newton sees the loads' dependence on the state when
the journal starts to stick.  Friction off adds nothing: the frictionless joint gives bit-identical
results to the former one.

Misuse is loud, not silent (:class:`JointMisuse`, raised from inside the solve, where Exudyn
reports it as a ``ModelError`` carrying this message):

- a post-step function set with ``mbs.SetPostStepUserFunction`` after this joint replaces its
  bookkeeping: the force callback notices a step ending without the bookkeeping having run;
- solving the same system again without ``model.reset(mbs)``: the bookkeeping sees time go
  backwards;
- bodies that leave Exudyn's XY plane: an eccentricity with an out-of-plane part larger than the
  clearance (the contact only sees the in-plane part).

Lubrication (``joint.lubrication``, :class:`weftsim.input.params.Lubrication`): the oil film, the asperity
contact and the boundary friction of :mod:`weftsim.physics.lubricated` act at every state, in contact or
not, through the same connector and torque loads as friction (:mod:`.joint_friction`, with the kernel's
:func:`~weftsim.physics.lubricated.connector_lubricated_force`); ``model.friction.lubrication_history``
records (t, D'_lub, U_a, |f_film|, F_a, T_j) at every accepted state.  Build the joint with
``ClearanceJoint(..., lubrication=Lubrication(viscosity=...))``.

A worn joint (``ClearanceJoint(..., bearing_wear=..., journal_wear=...)``: worn depth tables, m, at equally
spaced angles over one turn of each body's frame, i.e. from the body's own x axis about Z): the contact
sees the local clearance c0 + h_b(psi_b) + h_j(psi_j) along the eccentricity
(:mod:`weftsim.physics.worn_joint`, the same worn clearance as weftsim's own engines), through the same
connector and loads as friction (the bodies' angles are read at every trial state).

A restitution outside the law's valid range (``law.valid_restitution``) is a warning.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import exudyn as exu
import numpy as np
from exudyn.itemInterface import ObjectConnectorCartesianSpringDamper

from weftsim.joint.contact import make_law
from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.joint_friction import JointFriction
from weftsim.exudyn_engine.onset import OnsetTracker, penetration_state
from weftsim.physics.joint import joint_parameters
from weftsim.physics.wear import wear_block
from weftsim.input.params import ClearanceJoint

if TYPE_CHECKING:
    from collections.abc import Callable

    import exudyn.exudynCPP  # the index classes' module (exudyn's stub imports them from itself)

    from weftsim.joint.contact import _Law

ROUTES = callbacks.ROUTES
DEFAULT_ROUTE = callbacks.DEFAULT_ROUTE

_HOOKS = "weftsim_post_step_hooks"


class JointMisuse(RuntimeError):
    """The clearance joint is used in a way that would give wrong results silently."""


OVERWRITTEN_POST_STEP = ("the clearance joint's post-step bookkeeping did not run after a step (was "
                         "mbs.SetPostStepUserFunction called after add_clearance_joint? it replaces the joint's "
                         "function): set your function before add_clearance_joint, or add it with "
                         "weftsim.exudyn_engine.clearance_joint.register_post_step(mbs, function)")


def out_of_plane_message(e_z: float, clearance: float) -> str:
    """One line for an eccentricity with an out-of-plane part |e_z| > c."""
    return (f"the clearance joint's bodies left Exudyn's XY plane: the eccentricity has an out-of-plane part "
            f"e_z = {e_z:.3g} m, more than the clearance c = {clearance:.3g} m; the joint acts in the XY plane "
            "only (joint axis Z): build the bodies in the XY plane (2-D bodies) or constrain their motion along Z")


def _check_plane(e_z: float, clearance: float) -> None:
    if abs(e_z) > clearance:
        raise JointMisuse(out_of_plane_message(e_z, clearance))


def register_post_step(mbs: exu.MainSystem, hook: Callable[[exu.MainSystem, float], object]) -> None:
    """Run ``hook(mbs, t)`` after every accepted step, alongside other registered hooks.

    Exudyn has one post-step function per system; the first registration installs a
    dispatcher (keeping a function the user had set) and later ones append to it.  A hook
    returning ``False`` stops the simulation after the current step.
    """
    hooks = mbs.variables.get(_HOOKS)
    if hooks is None:
        hooks = []
        previous = mbs.GetPostStepUserFunction()
        if isinstance(previous, dict) and callable(previous.get("function")):
            hooks.append(previous["function"])
        mbs.variables[_HOOKS] = hooks

        def post_step(mbs, t):
            go = True
            for h in hooks:
                if h(mbs, t) is False:
                    go = False
            return go

        mbs.SetPostStepUserFunction(post_step)
    hooks.append(hook)


@dataclass
class ClearanceJointModel:
    """Handle of one clearance joint in an Exudyn system.

    Attributes
    ----------
    connector : exudyn ObjectIndex
        The ``ObjectConnectorCartesianSpringDamper``; its ``Force`` output is F_N n (the
        force on the bearing; the journal gets the opposite), ``Displacement`` is e.
    joint : ClearanceJoint
    law : contact law of :mod:`weftsim.joint.contact`
    route : str
        Callback route in use (one of :data:`ROUTES`).
    tracker : OnsetTracker
        Contact state, held impact velocity, per-step history, first contact time.
    """

    connector: object
    joint: ClearanceJoint
    law: object
    route: str
    tracker: OnsetTracker
    # [latest trial time seen by the force callback] (the overwritten post-step check, add_clearance_joint)
    trial_time: list = field(default_factory=lambda: [0.0], repr=False)
    # friction force and moments (joint.friction_coefficient > 0), and the film of a lubricated joint
    friction: JointFriction | None = None

    def state(self, mbs: exu.MainSystem) -> tuple[float, float]:
        """Current (delta, delta_dot) of the joint, m and m/s (a worn joint: at the local clearance)."""
        if self.joint.is_worn:
            if self.friction is None:  # add_clearance_joint gives a worn joint its JointFriction
                raise JointMisuse("a worn clearance joint needs its JointFriction (build it with add_clearance_joint)")
            return self.friction.penetration(mbs)
        u = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Displacement)
        v = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Velocity)
        return penetration_state(u[0], u[1], v[0], v[1], self.joint.clearance)

    def reset(self, mbs: exu.MainSystem, t0: float = 0.0) -> None:
        """Start the bookkeeping from the current (assembled, initial) state of ``mbs``."""
        u = mbs.GetObjectOutput(self.connector, exu.OutputVariableType.Displacement)
        _check_plane(u[2], self.joint.clearance)
        delta, rate = self.state(mbs)
        self.tracker = OnsetTracker(self.joint.clearance, self.joint.min_impact_velocity, t0, delta, rate,
                                    self.joint.impact_velocity_rule)
        mbs.SetObjectParameter(self.connector, "stiffness", self.tracker.callback_state)
        self.trial_time[0] = t0
        if self.friction is not None:
            self.friction.history.clear()
            self.friction.lubrication_history.clear()


def add_clearance_joint(mbs: exu.MainSystem, marker_bearing: exudyn.exudynCPP.MarkerIndex,
                        marker_journal: exudyn.exudynCPP.MarkerIndex,
                        joint: ClearanceJoint, law: _Law | None = None, callback: str = "auto",
                        call_counter: list | None = None) -> ClearanceJointModel:
    """Add a planar revolute clearance joint between two position markers.

    Parameters
    ----------
    mbs : exudyn.MainSystem
        System in which both bodies move in the XY plane (joint axis = Z).
    marker_bearing, marker_journal : exudyn MarkerIndex
        Position markers at the bearing centre P_b and at the journal centre P_j.
    joint : ClearanceJoint
        Clearance c > 0, radii, materials, law name, restitution, v_min.
    law : contact law, optional
        Defaults to ``weftsim.joint.contact.make_law(joint)``; any law of that library.
    callback : {"auto", "python", "numba"}
        Force callback route; "auto" = :data:`DEFAULT_ROUTE` (the fastest measured).
    call_counter : list, optional
        One-element list counting callback calls (python route only; benchmarks).

    Returns
    -------
    ClearanceJointModel

    Raises
    ------
    ValueError
        For c <= 0 (use an ideal revolute joint) or an unknown route.
    JointMisuse
        During the solve (Exudyn reports it as ``exudyn.ModelError`` with this message): a post-step
        function set after this call, a second solve without :meth:`ClearanceJointModel.reset`, bodies
        leaving the XY plane (module docstring).

    Warns
    -----
    UserWarning
        When ``joint.restitution`` is outside the law's ``valid_restitution``.
    """
    if not joint.clearance > 0.0:
        raise ValueError(f"`clearance` must be > 0 for a clearance joint, got {joint.clearance}; "
                         "use ObjectJointRevolute2D for an ideal joint")  # fmt: skip
    if callbacks.route_error(callback):
        raise ValueError(callbacks.route_error(callback))
    law = make_law(joint) if law is None else law
    lo, hi = law.valid_restitution
    if not lo <= joint.restitution <= hi:
        warnings.warn(f"`restitution` = {joint.restitution:g} is outside {lo:g}..{hi:g}, the range the "
                      f"'{law.name}' law's damping was derived for: its contacts will not return this restitution; "
                      "choose a law valid there (e.g. 'flores' for any ce)", UserWarning, stacklevel=2)
    route = callbacks.resolve_route(callback)
    if call_counter is not None and (route != "python" or joint.friction_coefficient > 0.0 or joint.is_lubricated
                                     or joint.is_worn):
        raise ValueError("`call_counter` works with callback='python', no friction, no lubrication and no wear only")
    c, v_min = joint.clearance, joint.min_impact_velocity
    max_approach = joint.impact_velocity_rule == "max_approach"
    tracker = OnsetTracker(c, v_min, rule=joint.impact_velocity_rule)  # checks the rule's name
    friction = None
    model: ClearanceJointModel  # built below, after the connector; the callbacks read it only once it is
    if joint.friction_coefficient > 0.0 or joint.is_lubricated or joint.is_worn:
        prm = joint_parameters(joint, law)
        if joint.is_worn:  # the wear block after the joint block (weftsim.physics.worn_joint)
            prm = np.concatenate([prm, wear_block(joint.bearing_wear, joint.journal_wear)])
        friction = JointFriction(mbs, marker_bearing, marker_journal, prm, route,
                                 lambda: model.tracker.callback_state)  # fmt: skip
        force = friction.spring_force
    elif route == "python":
        force = callbacks.make_python_force(law, c, v_min, call_counter, max_approach)
    else:
        force = callbacks.make_numba_force(law, c, v_min, max_approach)
    # The latest trial time the callback saw.  A call at a later time while the tracker's last accepted
    # time is still below that one means a step ended there and the bookkeeping never ran.
    trial = [tracker.t]

    def checked_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        if t > trial[0]:
            if trial[0] > model.tracker.t:
                raise JointMisuse(OVERWRITTEN_POST_STEP)
            trial[0] = t
        return force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset)

    connector = mbs.AddObject(ObjectConnectorCartesianSpringDamper(
        markerNumbers=[marker_bearing, marker_journal],
        stiffness=tracker.callback_state, damping=[0.0, 0.0, 0.0], offset=[0.0, 0.0, 0.0],
        springForceUserFunction=checked_force,
    ))  # fmt: skip
    model = ClearanceJointModel(connector, joint, law, route, tracker, trial, friction)
    if friction is not None:
        friction.install(mbs, connector)
    displacement = exu.OutputVariableType.Displacement
    velocity = exu.OutputVariableType.Velocity

    def accept(mbs, t):
        u = mbs.GetObjectOutput(connector, displacement)
        v = mbs.GetObjectOutput(connector, velocity)
        _check_plane(u[2], c)
        if t < model.tracker.t:
            raise JointMisuse(f"the clearance joint's time went backwards (from {model.tracker.t:.6g} s to {t:.6g} s): "
                              "the system is solved again; call model.reset(mbs) before every new solve")
        trial[0] = min(trial[0], t)
        if friction is not None:
            friction.accept(mbs, t)
        if joint.is_worn:
            delta, rate = friction.penetration(mbs)
        else:
            delta, rate = penetration_state(u[0], u[1], v[0], v[1], c)
        model.tracker.accept(t, delta, rate)
        mbs.SetObjectParameter(connector, "stiffness", model.tracker.callback_state)
        return True

    register_post_step(mbs, accept)
    return model

