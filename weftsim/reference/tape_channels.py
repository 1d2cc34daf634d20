"""Output channels of a run with the flexible tape, in numba, from the equations that were integrated.

:data:`weftsim.post.results.CHANNELS` (the rapier's channels are the wheel's pitch-circle motion; the energy
channels hold the tape: its kinetic energy in ``kinetic_energy_J``, its strain energy in
``potential_energy_J``, its damping and guide friction in ``dissipated_energy_J``) and
:data:`weftsim.post.results.TAPE_CHANNELS`, from :func:`weftsim.physics.tape.chain_tape`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from weftsim.input.params import Scene
from weftsim.physics import chain as kc
from weftsim.physics import tape as kt
from weftsim.physics.laws import elastic_energy
from weftsim.post.results import CHANNELS, TAPE_CHANNELS
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.reference.compiled_channels import crank_side_eval, crank_side_table


@njit(cache=True, error_model="numpy")
def _fill_tape(prm, table, a0, ratio, time, states, contact, impact, out):
    """Rows of CHANNELS then TAPE_CHANNELS (but the frequency, column -2: filled in Python) into out."""
    omega = prm[kc.OMEGA]
    n = kt.modes(prm)
    d = np.empty(2 * n + 6)
    start = np.empty(4)
    crank = np.empty(4)
    crank_side_eval(table, 0.0, start)
    work0 = 0.5 * start[0] * omega * omega + start[2]
    base = len(CHANNELS)
    h = prm[kt.TAPE + kt.N_SCALARS + n:kt.TAPE + kt.N_SCALARS + 2 * n]
    head = prm[kt.TAPE + kt.HEAD]
    guide = prm[kt.TAPE + kt.GUIDE_MU] * prm[kt.TAPE + kt.GUIDE_G] * head
    for i in range(time.size):
        t = time[i]
        y = states[i]
        r = kt.chain_tape(prm, t, y, contact[i], impact[i], d)
        q3, f_n, delta, sa, ca, sp, cp, root, head_v, head_a, lam, kin_tape, strain = r[:13]
        y6 = kt.chain_state(prm, y)
        crank_side_eval(table, omega * t, crank)
        a, da, dpsi = y[0], y6[2], y6[3]
        m12 = -prm[kc.COUPLING] * (cp * ca + sp * sa)
        kin48 = 0.5 * (prm[kc.M11] * da * da + 2.0 * m12 * da * dpsi + prm[kc.M22] * dpsi * dpsi) + kin_tape
        pot48 = prm[kc.ROD_MASS] * prm[kc.GRAVITY] * (prm[kc.L_FG] * sa - 0.5 * prm[kc.L_EF] * sp) + strain
        kin13 = 0.5 * crank[0] * omega * omega
        ecc = kc.eccentricity(prm[:kc.WEAR_E], t, y6)
        head_s = ratio * (a - a0)
        for k in range(n):
            head_s += h[k] * y[2 + k]
        out[i, 0] = t
        out[i, 1] = omega * t * (180.0 / math.pi)
        out[i, 2] = ratio * (a - a0)
        out[i, 3] = ratio * da
        out[i, 4] = ratio * d[n + 2]
        out[i, 5] = 0.5 * crank[1] * omega * omega + crank[3] - q3
        out[i, 6] = f_n
        out[i, 7] = delta
        out[i, 8] = ecc[0]
        out[i, 9] = ecc[1]
        out[i, 10] = impact[i] if contact[i] else 0.0
        out[i, 11] = 1.0 if (contact[i] and delta > 0.0) else 0.0
        out[i, 12] = kin13 + kin48
        out[i, 13] = crank[2] + pot48
        out[i, 14] = elastic_energy(prm[kc.KIND], prm[kc.COEF], prm[kc.CLEARANCE], delta)
        out[i, 15] = kin13 + crank[2] - work0 + y[2 * n + 4]
        out[i, 16] = y[2 * n + 5]
        out[i, 17] = kc.penetration(prm[:kc.WEAR_E], t, y6)[1]
        out[i, base] = head_s
        out[i, base + 1] = head_v
        out[i, base + 2] = head_a
        out[i, base + 3] = root
        # Newton on the head: m a_head = (compression at the head) + guide friction.
        out[i, base + 4] = -head * head_a - guide * math.tanh(head_v / kt.V_GUIDE)
        out[i, base + 5] = lam
        out[i, base + 6] = 0.0
        out[i, base + 7] = strain


def tape_channels(scene: Scene, time: np.ndarray, states: np.ndarray, contact: np.ndarray,
                  impact: np.ndarray) -> dict[str, np.ndarray]:
    """All CHANNELS and TAPE_CHANNELS at the given rows of a flexible-tape run (``contact`` bool, ``impact``
    (n,) at E), as :func:`weftsim.reference.compiled_channels.compiled_channels` gives a rigid run's."""
    from weftsim.model.tape import first_frequency, tape_of

    time = np.ascontiguousarray(time, dtype=float)
    prm = pack_parameters(scene)
    y0 = initial_state(scene)
    states = np.ascontiguousarray(states, dtype=float).reshape(time.size, y0.size)
    names = CHANNELS + TAPE_CHANNELS
    out = np.empty((time.size, len(names)))
    _fill_tape(prm, crank_side_table(scene), float(y0[0]), scene.geometry.rapier_ratio, time, states,
               np.asarray(contact, dtype=np.bool_), np.asarray(impact, dtype=float), out)
    channels = dict(zip(names, np.ascontiguousarray(out.T)))
    channels["tape_frequency_hz"] = first_frequency(tape_of(scene), channels["tape_free_length_m"])
    return channels
