"""Force callbacks of the clearance connector: three routes to the same contact law.

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
                                      (onset.damping_rate: resting contact)

(:func:`weftsim.exudyn_engine.onset.callback_impact_velocity` is the one scalar definition.)

Routes (all compute the same force; tests check it):

- ``"python"``: plain-``math`` closure around ``law.scalar()``.
- ``"symbolic"``: an Exudyn symbolic user function (expression tree evaluated in C++,
  no Python in the Newton loop) built from the law's coefficients by
  :func:`symbolic_elastic_force`.
- ``"numba"``: a Python wrapper around an ``@njit`` core (Exudyn passes ``MainSystem``
  as first argument, so the jitted function cannot be the callback itself).
"""

from __future__ import annotations

import math

import exudyn as exu

from weftsim.contact import ElasticFoundation, VariableKD
from weftsim.exudyn_engine.onset import RESTING_RATE_FRACTION, callback_impact_velocity, damping_rate

# Smallest |e| used as a divisor in the symbolic route (which evaluates both branches of
# IfThenElse): any positive value below round-off of a clearance works, m.
_TINY_LENGTH = 1e-300


def make_python_force(law, clearance: float, min_impact_velocity: float, counter: list | None = None,
                      max_approach: bool = True):
    """Plain-Python callback around ``law.scalar()`` (about 1.5 us per call).

    ``counter``, if given, is a one-element list incremented per call (benchmarks only);
    ``max_approach`` selects the held impact velocity rule (False: ``"onset"``).
    """
    normal_force = law.scalar()
    c, v_min, sqrt = clearance, min_impact_velocity, math.sqrt
    impact_velocity, damped = callback_impact_velocity, damping_rate
    v_dead = RESTING_RATE_FRACTION * min_impact_velocity

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        ex = displacement[0]
        ey = displacement[1]
        length = sqrt(ex * ex + ey * ey)
        delta = length - c
        if delta <= 0.0:
            return [0.0, 0.0, 0.0]
        nx = ex / length
        ny = ey / length
        rate = velocity[0] * nx + velocity[1] * ny
        v_imp = impact_velocity(stiffness[0], stiffness[1], stiffness[2], delta, rate, v_min, max_approach)
        f = normal_force(delta, damped(rate, v_dead), v_imp)
        return [f * nx, f * ny, 0.0]

    if counter is None:
        return spring_force

    def counted(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        counter[0] += 1
        return spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset)

    return counted


def make_numba_force(law, clearance: float, min_impact_velocity: float, max_approach: bool = True):
    """Python wrapper around an ``@njit`` core that computes the whole force (needs numba)."""
    import numba  # optional dependency: only this route needs it

    normal_force = law.numba()
    impact_velocity, damped = numba.njit(callback_impact_velocity), numba.njit(damping_rate)
    c, v_min, v_dead = clearance, min_impact_velocity, RESTING_RATE_FRACTION * min_impact_velocity

    @numba.njit(cache=False)
    def core(ex, ey, vx, vy, held, delta0, rate0):
        length = math.sqrt(ex * ex + ey * ey)
        delta = length - c
        if delta <= 0.0:
            return 0.0, 0.0
        nx = ex / length
        ny = ey / length
        rate = vx * nx + vy * ny
        v_imp = impact_velocity(held, delta0, rate0, delta, rate, v_min, max_approach)
        f = normal_force(delta, damped(rate, v_dead), v_imp)
        return f * nx, f * ny

    core(1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0)  # compile now, not inside the first step

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        fx, fy = core(displacement[0], displacement[1], velocity[0], velocity[1],
                      stiffness[0], stiffness[1], stiffness[2])  # fmt: skip
        return [fx, fy, 0.0]

    return spring_force


def symbolic_elastic_force(law, penetration, esym):
    """F_el = K(delta) delta^1.5 as an expression of ``esym`` (Exudyn symbolic or ``math``-like).

    ``penetration`` must already be clamped to >= 0.  Supported: every constant-stiffness
    law (``stiffness_constant``), :class:`~weftsim.contact.VariableKD` and
    :class:`~weftsim.contact.ElasticFoundation`; the formulas are those of their docstrings,
    with the coefficients taken from the law object.
    """
    d = penetration
    d15 = d * esym.sqrt(d)
    if isinstance(law, VariableKD):
        a, c = law.modulus_factor, law.clearance
        return a * esym.sqrt(2.0 * d * (3.0 * c + 2.0 * d) * (3.0 * c + 2.0 * d)
                             / ((c + d) * (c + d) * (c + d))) * d15  # fmt: skip
    if isinstance(law, ElasticFoundation):
        return law.length_modulus / esym.sqrt(2.0 * (law.clearance + d)) * d15
    if hasattr(law, "stiffness_constant"):
        return law.stiffness_constant * d15
    raise NotImplementedError(
        f"no symbolic form for contact law {law.name!r}; use callback 'python' or 'numba'"
    )


def symbolic_clearance_force(law, clearance: float, v_min: float, ex, ey, vx, vy, stiffness,
                             max_approach: bool = True):
    """Force on the journal ``[fx, fy, 0]`` as an Exudyn symbolic expression.

    ``(ex, ey)`` is the eccentricity P_j - P_b and ``(vx, vy)`` its rate; ``stiffness`` holds the
    held impact velocity and the last accepted (penetration, rate), from which the onset within the
    step is interpolated.  The impact velocity is that of
    :func:`weftsim.exudyn_engine.onset.callback_impact_velocity` (``max_approach`` selects the rule at
    build time, so the ``"onset"`` rule's expression has no extra node).  Both branches of every
    ``IfThenElse`` may be evaluated, so divisors and square roots are guarded.  Shared by the
    rigid-body and kinematic-tree models.
    """
    esym = exu.symbolic
    real = esym.Real
    xi = law.hysteresis
    length = esym.sqrt(ex * ex + ey * ey)
    delta = length - real(clearance)
    safe = esym.max(length, real(_TINY_LENGTH))
    nx = ex / safe
    ny = ey / safe
    rate = vx * nx + vy * ny
    held = stiffness[0]
    delta0 = stiffness[1]
    rate0 = stiffness[2]
    span = esym.min(delta0 - delta, real(-_TINY_LENGTH))
    s = esym.min(esym.max(delta0 / span, real(0.0)), real(1.0))
    onset = rate0 + s * (rate - rate0)
    if max_approach:  # max(held or onset, rate): also covers a non-positive onset estimate
        v = esym.max(esym.IfThenElse(delta0 > real(0.0), held, onset), rate)
    else:
        v = esym.IfThenElse(delta0 > real(0.0), held, esym.IfThenElse(onset > real(0.0), onset, rate))
    v_imp = esym.max(v, real(v_min))
    v_dead = RESTING_RATE_FRACTION * v_min
    damped = rate - esym.min(esym.max(rate, real(-v_dead)), real(v_dead))  # onset.damping_rate
    f_el = symbolic_elastic_force(law, esym.max(delta, real(0.0)), esym)
    f = esym.max(f_el * (real(1.0) + real(xi) * damped / v_imp), real(0.0))
    f = esym.IfThenElse(delta > real(0.0), f, real(0.0))
    return [f * nx, f * ny, real(0.0)]


def make_symbolic_force(mbs, law, clearance: float, min_impact_velocity: float, max_approach: bool = True):
    """Exudyn symbolic user function of the clearance force (expression tree, C++ evaluation).

    Both branches of every ``IfThenElse`` may be evaluated, so divisors and square roots
    are guarded (clamped penetration, |e| >= tiny, onset fraction clamped to [0, 1]).
    Keep the returned object alive as long as the system (Exudyn's requirement).
    """
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    c, v_min = clearance, min_impact_velocity

    def springForceUserFunction(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return symbolic_clearance_force(law, c, v_min, displacement[0], displacement[1], velocity[0],
                                        velocity[1], stiffness, max_approach)

    return CreateSymbolicUserFunction(
        mbs, springForceUserFunction, "springForceUserFunction",
        itemTypeName="ObjectConnectorCartesianSpringDamper",
    )  # fmt: skip
