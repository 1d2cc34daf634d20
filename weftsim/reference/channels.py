"""Output channels of a clearance-mode run, evaluated from the integrated states.

Everything is recomputed with the compiled right-hand side that was integrated
(:func:`weftsim.physics.chain.chain`, row by row in :mod:`.compiled_channels`), so the rapier
acceleration is the equation of motion's a'' (not a finite difference) and the contact force is
the one the solver saw.

Energy channels (docs/physics.md section 4, COMMON interface)::

    kinetic   = 1/2 J13(theta) omega^2 + 1/2 q'^T M(q) q'
    potential = U13(theta) + m4 g z4
    contact   = integral_0^delta F_el  (0 when delta <= 0)
    driving work W = integral T omega dt = [1/2 J13 omega^2 + U13]_0^t + W3(t)
    dissipated = D(t)

with W3 = integral -Q3 omega dt and D = integral (F_N - F_el) delta_dot - F_T v_T dt the
two integrated states.  The closed form of the crank-side part is exact at constant omega
because T omega = d/dt(1/2 J13 omega^2 + U13) - Q3 omega.
"""

from __future__ import annotations

import numpy as np

from weftsim.input.params import Scene


def clearance_channels(scene: Scene, time: np.ndarray, states: np.ndarray, contact: np.ndarray,
                       impact: np.ndarray) -> dict[str, np.ndarray]:
    """All :data:`weftsim.post.results.CHANNELS` at the given times.

    Parameters
    ----------
    scene : Scene
    time : (N,) s
    states : (N, 6) [a, psi, a', psi', W3, D]
    contact : (N,) bool, the segment's mode (contact force evaluated or not)
    impact : (N,) m/s, held, floored impact velocity of the segment (ignored in free flight)

    Returns
    -------
    dict of str to (N,) ndarray
        ``penetration_m`` is delta = |e| - c, negative in free flight;
        ``in_contact`` is 1 where delta > 0 in a contact segment, else 0;
        ``impact_velocity_m_s`` is the held value in contact segments, 0 in free flight;
        ``penetration_rate_m_s`` is delta_dot = e_dot . n in both modes (the plausibility
        checks read the approach rate at each onset from it).
    """
    from weftsim.reference.compiled_channels import compiled_channels

    return compiled_channels(scene, time, states, contact, impact)
