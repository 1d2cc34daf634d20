"""Output channels of a clearance-mode run, computed in numba (post-processing of both paths).

The channels come from the equations that were integrated (see
:func:`weftsim.reference.channels.clearance_channels` for the energy bookkeeping), at ~0.1 us per row:

- the chain terms (a'', F_N, delta, e, Q3) from the compiled right-hand side
  (:mod:`weftsim.physics.chain`), the elastic energy from :func:`weftsim.physics.laws.elastic_energy`;
- the crank-side terms J13, J13', U13, U13' of :mod:`weftsim.model.ideal`, which depend on
  theta only and are periodic and analytic: they are sampled from those functions once per
  mechanism (:data:`TABLE_POINTS` per revolution) and read back through a periodic cubic
  spline, exact to ~1e-12 of their range (:func:`crank_side_table`; the closed forms are not
  written a second time).

"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from weftsim.input.params import Geometry, Inertia, Scene
from weftsim.physics.chain import (
    COEF, COUPLING, GRAVITY, KIND, L_EF, L_FG, M11, M22, OMEGA, ROD_MASS, chain, crank_motion, local_clearance, penetration,
)  # fmt: skip
from weftsim.physics import chain_f as kf
from weftsim.physics.chain_f import is_plain
from weftsim.physics.python import specialize
from weftsim.physics.laws import elastic_energy
from weftsim.model.dynamics import initial_state, pack_parameters
from weftsim.post.results import CHANNELS, JOINT_F_CHANNELS

TABLE_POINTS = 4096  # spline knots per revolution: interpolation error ~ 5/384 h^4 |f''''| ~ 1e-12 relative


def periodic_spline(values: np.ndarray, h: float) -> np.ndarray:
    """Coefficients (function, interval, power) of the periodic cubic spline through ``values``.

    ``values`` (n, m): m functions at n equally spaced knots x_i = i h of one period (the knot
    x_n = x_0 is implied).  The second derivatives M solve the circulant system
    M_(i-1) + 4 M_i + M_(i+1) = 6 (y_(i+1) - 2 y_i + y_(i-1)) / h^2, diagonal in Fourier space
    (eigenvalues 4 + 2 cos(2 pi k / n)); on [x_i, x_i+1], in powers of x - x_i (highest first):
    (M_(i+1) - M_i) / 6h,  M_i / 2,  (y_(i+1) - y_i) / h - h (2 M_i + M_(i+1)) / 6,  y_i.
    The same interpolant as ``scipy.interpolate.CubicSpline(bc_type="periodic")`` (tested), without
    importing scipy in every run.
    """
    y = values
    y_next = np.roll(y, -1, axis=0)
    rhs = 6.0 * (y_next - 2.0 * y + np.roll(y, 1, axis=0)) / h**2
    k = np.arange(y.shape[0])[:, None]
    m = np.fft.ifft(np.fft.fft(rhs, axis=0) / (4.0 + 2.0 * np.cos(2.0 * math.pi * k / y.shape[0])), axis=0).real
    m_next = np.roll(m, -1, axis=0)
    coefficients = np.stack([(m_next - m) / (6.0 * h), 0.5 * m, (y_next - y) / h - h * (2.0 * m + m_next) / 6.0, y])
    return np.ascontiguousarray(np.transpose(coefficients, (2, 1, 0)))


@functools.lru_cache(maxsize=16)
def _table(geometry: Geometry, inertia: Inertia) -> np.ndarray:
    from weftsim.model.ideal import crank_side_inertia, crank_side_potential

    scene = Scene(geometry=geometry, inertia=inertia)
    theta = np.linspace(0.0, 2.0 * math.pi, TABLE_POINTS, endpoint=False)
    j13, dj13 = crank_side_inertia(theta, scene)
    u13, du13 = crank_side_potential(theta, scene)
    return periodic_spline(np.stack([j13, dj13, u13, du13], axis=1), 2.0 * math.pi / TABLE_POINTS)


def crank_side_table(scene: Scene) -> np.ndarray:
    """Spline coefficients (4, TABLE_POINTS, 4) of J13, J13', U13, U13' over one revolution.

    Built from :func:`weftsim.model.ideal.crank_side_inertia` and
    :func:`~weftsim.model.ideal.crank_side_potential` once per mechanism (cached).
    """
    return _table(scene.geometry, scene.inertia)


@njit(cache=True, error_model="numpy")
def crank_side_eval(table: np.ndarray, theta: float, out: np.ndarray) -> None:
    """(J13, J13', U13, U13') at crank angle theta from :func:`crank_side_table` into out (4,)."""
    n = table.shape[1]
    h = 2.0 * math.pi / n
    x = theta - 2.0 * math.pi * math.floor(theta / (2.0 * math.pi))
    i = int(x / h)
    if i >= n:
        i = n - 1
    x -= i * h
    for k in range(4):
        out[k] = ((table[k, i, 0] * x + table[k, i, 1]) * x + table[k, i, 2]) * x + table[k, i, 3]


@njit(cache=True, error_model="numpy")
def _fill(prm, table, a0, ratio, time, states, contact, impact, out):
    """Rows of :data:`CHANNELS` (in that order) into out (n, 18)."""
    d = np.empty(6)
    start = np.empty(4)
    crank = np.empty(4)
    theta0, omega0, _ = crank_motion(prm, 0.0)  # (0, omega, 0) at constant speed
    crank_side_eval(table, theta0, start)
    work0 = 0.5 * start[0] * omega0 * omega0 + start[2]
    for i in range(time.size):
        t = time[i]
        y = states[i]
        q3, f_n, delta, ecc_y, ecc_z, sa, ca, sp, cp = chain(prm, t, y, contact[i], impact[i], d)[:9]
        theta, omega, acceleration = crank_motion(prm, t)  # omega t, omega, 0 at constant speed
        crank_side_eval(table, theta, crank)
        a, da, dpsi = y[0], y[2], y[3]
        m12 = -prm[COUPLING] * (cp * ca + sp * sa)  # -k cos(psi - a)
        kin48 = 0.5 * (prm[M11] * da * da + 2.0 * m12 * da * dpsi + prm[M22] * dpsi * dpsi)
        pot48 = prm[ROD_MASS] * prm[GRAVITY] * (prm[L_FG] * sa - 0.5 * prm[L_EF] * sp)
        kin13 = 0.5 * crank[0] * omega * omega
        out[i, 0] = t
        out[i, 1] = theta * (180.0 / math.pi)
        out[i, 2] = ratio * (a - a0)
        out[i, 3] = ratio * da
        out[i, 4] = ratio * d[2]
        # T = J13 theta'' + 1/2 J13' theta'^2 + U13' - Q3 (the crank side's inertia term only off constant speed)
        out[i, 5] = 0.5 * crank[1] * omega * omega + crank[3] - q3
        if acceleration != 0.0:
            out[i, 5] += crank[0] * acceleration
        out[i, 6] = f_n
        out[i, 7] = delta
        out[i, 8] = ecc_y
        out[i, 9] = ecc_z
        out[i, 10] = impact[i] if contact[i] else 0.0
        out[i, 11] = 1.0 if (contact[i] and delta > 0.0) else 0.0
        out[i, 12] = kin13 + kin48
        out[i, 13] = crank[2] + pot48
        out[i, 14] = elastic_energy(prm[KIND], prm[COEF], local_clearance(prm, t, ecc_y, ecc_z, 0.0, 0.0, y)[0],
                                   delta)
        out[i, 15] = kin13 + crank[2] - work0 + y[4]
        out[i, 16] = y[5]
        out[i, 17] = penetration(prm, t, y)[1]


# _fill for a plain scene (weftsim.physics.chain_f.PLAIN), compiled on first use.
_fill_plain = specialize(_fill, "plain", lean=True, counted=(), **kf.PLAIN)


@njit(cache=True, error_model="numpy")
def _fill_f(prm, table, a0, ratio, time, states, contact, impact, out):
    """Rows of :data:`CHANNELS` then :data:`JOINT_F_CHANNELS` into out (n, 25), clearance at F.

    ``contact``: mask (bit 0 E, bit 1 F); ``impact`` (n, 2).  The energy channels hold both joints.
    """
    omega = prm[OMEGA]
    n_dof = kf.degrees_of_freedom(prm)
    d = np.empty(2 * n_dof + 2)
    start = np.empty(4)
    crank = np.empty(4)
    crank_side_eval(table, 0.0, start)
    work0 = 0.5 * start[0] * omega * omega + start[2]
    loose_e = kf.joint_is_loose(prm, kf.JOINT_E_INDEX)
    jf = kf.JOINT_F
    n_base = len(CHANNELS)
    for i in range(time.size):
        t = time[i]
        y = states[i]
        mask = contact[i]
        q3, fe_n, delta_e, e_y, e_z, ff_n, delta_f, ef_y, ef_z, dda = kf.chain_f(prm, t, y, mask, impact[i], d)
        crank_side_eval(table, omega * t, crank)
        kin48, pot48 = kf.rod_energy(prm, t, y)
        kin13 = 0.5 * crank[0] * omega * omega
        out[i, 0] = t
        out[i, 1] = omega * t * (180.0 / math.pi)
        out[i, 2] = ratio * (y[0] - a0)
        out[i, 3] = ratio * y[n_dof]
        out[i, 4] = ratio * dda
        out[i, 5] = 0.5 * crank[1] * omega * omega + crank[3] - q3
        out[i, 6] = fe_n
        out[i, 7] = delta_e if loose_e else 0.0
        out[i, 8] = e_y
        out[i, 9] = e_z
        out[i, 10] = impact[i, 0] if mask & 1 else 0.0
        out[i, 11] = 1.0 if (mask & 1 and delta_e > 0.0) else 0.0
        out[i, 12] = kin13 + kin48
        out[i, 13] = crank[2] + pot48
        c_e, _, c_f, _ = kf.local_clearances(prm, t, y, kf.eccentricities(prm, t, y))  # c0 at a round joint
        out[i, 14] = elastic_energy(prm[jf + KIND], prm[jf + COEF], c_f, delta_f)
        if loose_e:
            out[i, 14] += elastic_energy(prm[KIND], prm[COEF], c_e, delta_e)
        out[i, 15] = kin13 + crank[2] - work0 + y[2 * n_dof]
        out[i, 16] = y[2 * n_dof + 1]
        out[i, 17] = kf.penetration_at(prm, t, y, kf.JOINT_E_INDEX)[1] if loose_e else 0.0
        out[i, n_base] = ff_n
        out[i, n_base + 1] = delta_f
        out[i, n_base + 2] = ef_y
        out[i, n_base + 3] = ef_z
        out[i, n_base + 4] = impact[i, 1] if mask & 2 else 0.0
        out[i, n_base + 5] = 1.0 if (mask & 2 and delta_f > 0.0) else 0.0
        out[i, n_base + 6] = kf.penetration_at(prm, t, y, kf.JOINT_F_INDEX)[1]


def compiled_channels(scene: Scene, time: np.ndarray, states: np.ndarray, contact: np.ndarray,
                      impact: np.ndarray) -> dict[str, np.ndarray]:
    """All :data:`~weftsim.post.results.CHANNELS` at the given rows (arguments as ``clearance_channels``).

    With clearance at F (``scene.joint_f``) also :data:`~weftsim.post.results.JOINT_F_CHANNELS`; then
    ``contact`` is the mask of the joints in contact (bit 0 E, bit 1 F) and ``impact`` (n, 2) their
    held impact velocities (:func:`weftsim.reference.compiled_run.integrate_compiled`).
    """
    time = np.ascontiguousarray(time, dtype=float)
    prm = pack_parameters(scene)
    table = crank_side_table(scene)
    a0 = float(initial_state(scene)[0])
    size = initial_state(scene).size
    states = np.ascontiguousarray(states, dtype=float).reshape(time.size, size)
    if scene.joint_f.is_ideal:
        out = np.empty((len(CHANNELS), time.size)).T  # rows written by the kernel, each channel contiguous
        fill = _fill_plain if is_plain(prm) else _fill
        fill(prm, table, a0, scene.geometry.rapier_ratio, time, states, np.asarray(contact, dtype=np.bool_),
              np.asarray(impact, dtype=float), out)  # fmt: skip
        channels = dict(zip(CHANNELS, out.T))
    else:
        names = CHANNELS + JOINT_F_CHANNELS
        out = np.empty((len(names), time.size)).T
        _fill_f(prm, table, a0, scene.geometry.rapier_ratio, time, states, np.asarray(contact, dtype=np.int64),
                np.ascontiguousarray(impact, dtype=float).reshape(time.size, 2), out)  # fmt: skip
        channels = dict(zip(names, out.T))
    if scene.joint.is_lubricated or scene.joint_f.is_lubricated:
        # The film and asperity channels; the asperities' potential joins the contact energy (the chain
        # books the film's, the boundary friction's and the asperities' hysteresis work as dissipated,
        # weftsim.physics.lubricated).
        from weftsim.joint.lubrication import lubrication_table

        lubricated, asperity_energy = lubrication_table(scene, prm, time, states)
        channels["contact_energy_J"] = channels["contact_energy_J"] + asperity_energy
        channels.update(lubricated)
    from weftsim.joint.load import joint_force_table

    channels.update(joint_force_table(scene, prm, time, states, channels))
    return channels
