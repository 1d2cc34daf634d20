"""Compiled core of the kinematic tree's contact force (the numba route of :mod:`.tree`).

The same equations as :func:`weftsim.exudyn_engine.tree.make_python_force`, written as a
module-level ``@njit(cache=True)`` function whose every scene-dependent number comes in one
float array: the parameters of :func:`weftsim.reference.compiled_kernel.pack_parameters`
(bearing motion, chain lengths, contact law, v_min, held-velocity rule), followed by
:data:`N_SLOTS` slots that the post-step bookkeeping and the core share:

    HELD .. HELD+2     callback memory [v_held, delta0, rate0] of the last accepted step
    STASH .. STASH+4   [t, delta, delta_dot, F_b,x, F_b,y] of the last call (F_b = F_N n on the bearing)
    CALLS              number of calls

A function with closure constants would be compiled again in every run (numba cannot reuse
its cache); this one compiles once per machine.  Imported only by the numba route, so the
python route never imports numba.
"""

from __future__ import annotations

import math

from numba import njit

from weftsim.exudyn_engine.onset import RESTING_RATE_FRACTION, callback_impact_velocity, damping_rate
from weftsim.reference.compiled_kernel import (
    CLEARANCE,
    L_EF,
    L_FG,
    L_OG,
    N_PARAMETERS,
    OMEGA,
    TRACK_MAX,
    V_MIN,
    crank_side,
    normal_force,
)

HELD, STASH, CALLS, N_SLOTS = 0, 3, 8, 9
_HELD, _STASH, _CALLS = N_PARAMETERS + HELD, N_PARAMETERS + STASH, N_PARAMETERS + CALLS

_impact_velocity = njit(cache=True)(callback_impact_velocity)
_damping_rate = njit(cache=True)(damping_rate)


@njit(cache=True)
def tree_force_core(state, t, a, q1, da, dq1):
    """Joint torques (Q0, Q1) of the contact force at time t and joint state (q, q_t); fills the stash.

    Journal P_j = G + L_FG u(a) + L_EF u(b), b = a + q1; e = P_j - P_b(t);
    Q1 = F_N L_EF (n_x sin b - n_y cos b), Q0 = F_N L_FG (n_x sin a - n_y cos a) + Q1.
    """
    state[_CALLS] += 1.0
    b_y, b_z, db_y, db_z, _ = crank_side(state, t)
    omega, l_fg, l_ef = state[OMEGA], state[L_FG], state[L_EF]
    b = a + q1
    db = da + dq1
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    ex = state[L_OG] + l_fg * ca + l_ef * cb - b_y
    ey = l_fg * sa + l_ef * sb - b_z
    length = math.sqrt(ex * ex + ey * ey)
    delta = length - state[CLEARANCE]
    state[_STASH], state[_STASH + 1] = t, delta
    state[_STASH + 2] = state[_STASH + 3] = state[_STASH + 4] = 0.0
    if length <= 0.0:
        return 0.0, 0.0
    nx = ex / length
    ny = ey / length
    rate = ((-l_fg * sa * da - l_ef * sb * db - omega * db_y) * nx
            + (l_fg * ca * da + l_ef * cb * db - omega * db_z) * ny)  # fmt: skip
    state[_STASH + 2] = rate
    if delta <= 0.0:
        return 0.0, 0.0
    v_min = state[V_MIN]
    v_imp = _impact_velocity(state[_HELD], state[_HELD + 1], state[_HELD + 2], delta, rate, v_min,
                             state[TRACK_MAX] > 0.5)  # fmt: skip
    f = normal_force(state, delta, _damping_rate(rate, RESTING_RATE_FRACTION * v_min), v_imp)
    state[_STASH + 3], state[_STASH + 4] = f * nx, f * ny
    gq1 = f * l_ef * (nx * sb - ny * cb)
    return f * l_fg * (nx * sa - ny * ca) + gq1, gq1
