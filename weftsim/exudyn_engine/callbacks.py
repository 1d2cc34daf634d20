"""Force callbacks of the clearance connector, built from the one kernel of the joint force.

Exudyn calls ``springForceUserFunction(mbs, t, itemNumber, displacement, velocity,
stiffness, damping, offset) -> [fx, fy, fz]`` of an ``ObjectConnectorCartesianSpringDamper``
between the bearing centre (marker 0) and the journal centre (marker 1), so in a planar
model in Exudyn's XY plane

    e = displacement[0:2]           eccentricity P_j - P_b, m
    e_dot = velocity[0:2]           its rate, m/s
    stiffness = [v_held, delta0, rate0]   memory of the last accepted step (see onset.py)

and the returned force f acts as -f on the journal and +f on the bearing, so
f = F_N n with n = e/|e| pulls the journal back to the bearing centre::

       bearing (marker 0)             delta = |e| - c,  delta_dot = e_dot . n
        .---------.                   v_imp = v_held               if delta0 > 0
       /  P_b --e--> P_j  \\  -> n            rate0 + s (delta_dot - rate0), s = delta0/(delta0 - delta)
        '---------'                               otherwise (onset inside this step; the trial
                                                  delta_dot if that is <= 0)
                                      "max_approach" rule: v_imp = max(v_imp, delta_dot)
                                      F_N = law(delta, delta_dot', max(v_imp, v_min))
                                      delta_dot' = delta_dot less a dead zone of +-1e-6 v_min

All of it is :func:`weftsim.physics.joint.connector_force` (and, for the kinematic tree, whose
bearing moves with the crank, :func:`weftsim.physics.chain.tree_joint_force`, through
:func:`weftsim.physics.joint.connector_friction_force`).  Routes:

- ``"numba"``: the compiled kernel called from a thin Python callback (numba's cache: nothing
  to compile in a new process after the first run on a machine);
- ``"python"``: the same kernel's plain-Python source
  (:func:`weftsim.physics.python.python_form`), for debugging and for machines where the compiled
  call is slower.

Removed: ``"symbolic"`` (an Exudyn expression tree, a second copy of every law; it measured no
faster on the rigid-body model and ~6x slower on the kinematic tree, docs/clearance-joint.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.physics import chain as kernel_chain
from weftsim.physics import joint as kernel_joint
from weftsim.physics.hold import RESTING_RATE_FRACTION
from weftsim.physics.python import python_form

if TYPE_CHECKING:
    from collections.abc import Callable

    from numba.core.dispatcher import Dispatcher

    from weftsim.joint.contact import _Law

ROUTES = ("python", "numba")
# Fastest route on the loom model, rigid body and kinematic tree (scripts/bench_callbacks.py,
# docs/clearance-joint.md).
DEFAULT_ROUTE = "numba"
REMOVED_ROUTES = {"symbolic": "the symbolic route was removed (it was a second copy of every contact law "
                              "and measured no faster); use callback 'auto', 'numba' or 'python'"}


def resolve_route(callback: str) -> str:
    """The route a ``callback`` setting runs on: "auto" is :data:`DEFAULT_ROUTE`."""
    return DEFAULT_ROUTE if callback == "auto" else callback


def route_error(callback: str) -> str | None:
    """One line naming what is wrong with a ``callback`` route name, or None if it is allowed."""
    if callback in REMOVED_ROUTES:
        return f"`callback` = {callback!r}: {REMOVED_ROUTES[callback]}"
    if callback not in ("auto",) + ROUTES:
        return f"`callback` must be one of {('auto',) + ROUTES}, got {callback!r}"
    return None


def connector_parameters(law: _Law, clearance: float, min_impact_velocity: float, max_approach: bool) -> np.ndarray:
    """The joint block of :mod:`weftsim.physics.joint` the connector force needs (no friction)."""
    prm = np.zeros(kernel_joint.N_JOINT)
    kind, coef, _, xi = law.parameters
    prm[kernel_joint.KIND], prm[kernel_joint.COEF], prm[kernel_joint.XI] = kind, coef, xi
    prm[kernel_joint.CLEARANCE] = clearance
    prm[kernel_joint.V_MIN] = min_impact_velocity
    prm[kernel_joint.TRACK_MAX] = 1.0 if max_approach else 0.0
    prm[kernel_joint.DEAD_RATE] = RESTING_RATE_FRACTION * min_impact_velocity
    return prm


def parameters_for_route(prm: np.ndarray, route: str) -> np.ndarray | list[float]:
    """The parameters as the route reads them fastest: a numpy array compiled, a list of floats in
    plain Python (numpy scalars would make every operation of the kernel's source ~5x slower)."""
    return prm.tolist() if route == "python" else prm


def kernel_form(function: Dispatcher, route: str) -> Callable:
    if route == "python":
        return python_form(function)
    if route == "numba":
        return function
    raise ValueError(route_error(route) or f"`callback` = {route!r} has no kernel form")


def loaded_kernel(function: Dispatcher, route: str, *example: object) -> Callable:
    """:func:`kernel_form` of ``function``, loaded (or compiled) now by one call with ``example``, not inside the
    first step.

    On the numba route it is the compiled entry point of the specialisation that call took: the dispatcher works
    out the specialisation again at every call from its arguments' types, which is 0.5 us of the 1.1-1.2 us a
    call of the tree's kernel costs from Python (nine arguments, measured 1 144 against 659 ns a call), and a
    callback passes the same types at every call (floats and its one parameter array).  The dispatcher itself
    where numba does not expose the entry point.
    """
    form = kernel_form(function, route)
    if route != "numba":
        return form
    form(*example)
    try:
        loaded = function.overloads[tuple(function.typeof_pyval(value) for value in example)]
    except KeyError:
        return form
    # numba's CompileResult gets its entry point when it is compiled or loaded from the cache (not in its stub).
    return getattr(loaded, "entry_point", form)


def make_force(law: _Law, clearance: float, min_impact_velocity: float, route: str = "numba",
               counter: list | None = None, max_approach: bool = True) -> Callable[..., list[float]]:
    """Callback of a connector between a bearing marker and a journal marker (fixed frame).

    ``route``: ``"numba"`` or ``"python"`` (module docstring); ``counter``, if given, is a
    one-element list incremented per call (benchmarks only); ``max_approach`` selects the held
    impact velocity rule (False: ``"onset"``).
    """
    prm = parameters_for_route(connector_parameters(law, clearance, min_impact_velocity, max_approach), route)
    force = loaded_kernel(kernel_joint.connector_force, route, prm, 1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0)

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        fx, fy, _, _ = force(prm, displacement[0], displacement[1], velocity[0], velocity[1],
                             stiffness[0], stiffness[1], stiffness[2])  # fmt: skip
        return [fx, fy, 0.0]

    if counter is None:
        return spring_force

    def counted(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        counter[0] += 1
        return spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset)

    return counted


def make_python_force(law: _Law, clearance: float, min_impact_velocity: float, counter: list | None = None,
                      max_approach: bool = True) -> Callable[..., list[float]]:
    """:func:`make_force` on the ``"python"`` route."""
    return make_force(law, clearance, min_impact_velocity, "python", counter, max_approach)


def make_numba_force(law: _Law, clearance: float, min_impact_velocity: float,
                     max_approach: bool = True) -> Callable[..., list[float]]:
    """:func:`make_force` on the ``"numba"`` route."""
    return make_force(law, clearance, min_impact_velocity, "numba", None, max_approach)


# Indices into the tuple of :func:`weftsim.physics.chain.tree_joint_force` (the tree callback's ``stash[1]``).
STASH_DELTA, STASH_SLIDING_SPEED = 2, 9


def make_tree_force(prm: np.ndarray, memory: list, stash: list, route: str = "numba",
                    counter: list | None = None, powers: bool = False) -> Callable[..., list[float]]:
    """``forceUserFunction(mbs, t, itemNumber, q, q_t)`` of the kinematic tree: its joint forces.

    The contact of the moving bearing, projected on the joints by virtual work, is
    :func:`weftsim.physics.chain.tree_joint_force`.  ``prm``: the scene's kernel parameter array
    (:func:`weftsim.model.dynamics.pack_parameters`, friction included); ``memory`` =
    [v_held, delta0, rate0] of the last accepted step (written by the post-step bookkeeping); every
    call leaves [t, (Q0, Q1, delta, delta_dot, F_b,x, F_b,y, F_N, M_b, F_T v_T, v_T, D'_lub, U_a, W3', D')] in
    ``stash``, the kernel's tuple as it returned it (:data:`STASH_DELTA` and the other indices; F_b = F_N n -
    F_T t, the force on the bearing, plus the film's and asperities' of a lubricated joint; M_b its moment;
    F_T v_T the dry friction power; v_T the sliding speed; D'_lub and U_a the lubricated part's dissipated
    power and the asperity potential, 0 when dry; W3' and D' the drawn and dissipated powers): the
    last call of an accepted explicit step is at its end state (the last DOPRI5 / ODE23 stage), so the
    bookkeeping needs no extra evaluation.  ``powers``: the tree has two more joints whose accelerations
    are W3' and D' (:func:`weftsim.exudyn_engine.tree.build_tree`), so the callback returns four forces.
    The parameters the callback reads are its attribute ``prm`` (a copy; :mod:`.friction_segments` sets the
    friction entries of it).
    """
    prm = prm.copy()
    prm[kernel_joint.DEAD_RATE] = RESTING_RATE_FRACTION * prm[kernel_joint.V_MIN]
    route_prm = parameters_for_route(prm, route)
    force = loaded_kernel(kernel_chain.tree_joint_force, route, route_prm, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0)
    counter = [0] if counter is None else counter

    def tree_force(mbs, t, itemNumber, q, q_t):
        counter[0] += 1
        stash[1] = out = force(route_prm, t, q[0], q[1], q_t[0], q_t[1], memory[0], memory[1], memory[2])
        stash[0] = t
        return [out[0], out[1], out[12], out[13]] if powers else [out[0], out[1]]

    setattr(tree_force, "prm", route_prm)  # a function attribute (mypy has no type for one)
    return tree_force
