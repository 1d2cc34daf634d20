"""The contact of a worn joint E at given states of the chain 4-8 (the kinematic tree's channels).

An engine that does not integrate the reference chain's state y (the Exudyn kinematic tree) still
has the rod's angles a, psi and their rates at every accepted step.  Its channels of a worn joint
need the clearance the contact saw there, c = c0 + h_b(psi_b) + h_j(psi_j)
(:func:`weftsim.physics.chain.rod_clearance`, the one definition), and what follows from it: the
penetration delta = |e| - c, its rate e_dot . n - dc/dt and the law's elastic force and energy at
the local clearance, as :mod:`weftsim.reference.compiled_channels` writes them for the reference
engine.  A round joint gives c = c0 and dc/dt = 0.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from numba import njit

from weftsim.physics.chain import COEF, KIND, eccentricity, rod_clearance
from weftsim.physics.laws import elastic_energy, elastic_force

if TYPE_CHECKING:
    import numpy as np


@njit(cache=True, error_model="numpy")
def worn_contact_rows(prm: np.ndarray, time: np.ndarray, states: np.ndarray, out: np.ndarray) -> None:
    """Per row i of ``states`` (n, >= 4: a, psi, a', psi') at ``time[i]`` into ``out`` (n, 5):
    c (m), delta (m), delta_dot (m/s), F_el (N), U_el (J) of the joint at E (module docstring)."""
    for i in range(time.size):
        t = time[i]
        y = states[i]
        ecc_y, ecc_z, v_y, v_z = eccentricity(prm, t, y)[:4]
        length = math.sqrt(ecc_y * ecc_y + ecc_z * ecc_z)
        c, c_rate = rod_clearance(prm, t, ecc_y, ecc_z, v_y, v_z, y[1], y[3])
        delta = length - c
        out[i, 0] = c
        out[i, 1] = delta
        out[i, 2] = (v_y * ecc_y + v_z * ecc_z) / length - c_rate if length > 0.0 else 0.0
        out[i, 3] = elastic_force(prm[KIND], prm[COEF], c, delta)
        out[i, 4] = elastic_energy(prm[KIND], prm[COEF], c, delta)
