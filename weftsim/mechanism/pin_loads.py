"""Loads on the pins E and F of the ideal mechanism, from the kinematics alone (no simulation).

What a designer sizes a bushed pin with (docs/plausibility.md), over one crank revolution at the
scene's constant speed omega, with the ideal-joint kinematics of :mod:`weftsim.mechanism.kinematics`:

**Reflected mass.**  The chain behind a joint (behind E: rod 4, sector 5, pinion and rapier gear
6-7, rapier 8; behind F: members 5-8) is driven through the pin.  Its kinetic energy written with
the speed v of the pin centre, T = m_eff v^2 / 2, defines the mass the pin sees along its own
motion::

    m_eff = sum_i m_i |dv_i / dv|^2 + J_i (domega_i / dv)^2

Members 5-8 turn with the sector, so they count as one inertia about G,
J_s = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2.  At F (v = L_FG omega_FG) that gives the constant
m_eff,F = J_s / L_FG^2.  At E (v = L_OE omega_OE, the rocker's arm) every ratio is a derivative
with respect to the rocker-arm angle q::

    m_eff,E(q) = (m4 |dC4/dq|^2 + J4 (dtheta_EF/dq)^2 + J_s (dtheta_FG/dq)^2) / L_OE^2

finite at the rocker's reversals (where v = 0) and large near a dead point of the four-bar.

**Pin forces.**  Newton-Euler on the same chain: the sector group about G takes the tangential
part of the rod's force at F, J_s alpha_FG = L_FG F_t (the rapier's weight rests on its guide, the
sector and gears are balanced); the rod's two equations of motion (gravity along -z) give the rest.
With d = F - E and the force F_s of the rod on the sector, F_s = F_t n(theta_FG) + F_r u(theta_FG)::

    d x F_s = -(1/2) d x m4 (a_C4 - g) - J4 alpha_EF      (moments about the rod's centre)
    F_E = m4 (a_C4 - g) + F_s                              (force of the rocker on the rod at E)

Power balance F_E . v_E = dT/dt + m4 g v_C4,z holds exactly (tests/test_design_checks.py).

**Sliding speed.**  The pin surface slides at R_j abs(omega_rel): at E the rod turns against the
rocker (omega_EF - omega_OE), at F against the sector (omega_EF - omega_FG).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from weftsim.mechanism.kinematics import _cross, _normal, _unit, fourbar, linkage_state
from weftsim.input.params import Scene

# Crank angles of one revolution the ideal loads are evaluated at: 0.25 deg apart.  Measured against 0.025 deg:
# the peak pin force at E within 1e-6 and its mean within 5e-7, on the reference and the loom mechanisms.
SAMPLES = 1440


def sector_group_inertia(scene: Scene) -> float:
    """J_s = J5 + J67 (d5/d6)^2 + m8 (d5 d7/d6)^2, kg m^2: members 5-8 about G."""
    g, m = scene.geometry, scene.inertia
    return m.sector_inertia + m.pinion_gear_inertia * g.pinion_ratio**2 + m.rapier_mass * g.rapier_ratio**2


def reflected_mass_f(scene: Scene) -> float:
    """m_eff at F, kg: J_s / L_FG^2 (constant)."""
    return sector_group_inertia(scene) / scene.geometry.l_fg**2


def reflected_mass_e(theta: np.ndarray, scene: Scene, state=None) -> np.ndarray:
    """m_eff at E at crank angles ``theta`` (rad), kg (module docstring); ``state``: the scene's
    :func:`linkage_state` at ``theta`` when the caller has it."""
    g, m = scene.geometry, scene.inertia
    st = _state(theta, scene, state)
    fb = fourbar(st.theta_oe, g)  # derivatives with respect to the rocker-arm angle q
    d_com = 0.5 * (g.l_oe * _normal(st.theta_oe) + g.l_fg * fb.d_theta_fg[..., None] * _normal(fb.theta_fg))
    energy = (m.rod_mass * np.sum(d_com**2, axis=-1) + m.rod_inertia * fb.d_theta_ef**2
              + sector_group_inertia(scene) * fb.d_theta_fg**2)
    return energy / g.l_oe**2


@dataclass(frozen=True)
class PinLoads:
    """The ideal mechanism's loads on one pin over one revolution (equally spaced crank angles).

    Attributes
    ----------
    theta : ndarray
        Crank angles, rad.
    force : ndarray
        Magnitude of the pin force, N.
    sliding_speed : ndarray
        R_j abs(omega_rel) at the pin surface, m/s.
    reflected_mass : ndarray
        m_eff of the chain behind the pin, kg.
    """

    theta: np.ndarray
    force: np.ndarray
    sliding_speed: np.ndarray
    reflected_mass: np.ndarray


def pin_forces(theta: np.ndarray, scene: Scene, state=None) -> tuple[np.ndarray, np.ndarray]:
    """(F_E, F_s): force of the rocker on the rod at E and of the rod on the sector at F, N, shape (n, 2)
    in (y, z), at crank angles ``theta`` and the scene's constant crank speed (module docstring);
    ``state`` as in :func:`reflected_mass_e`."""
    g, m = scene.geometry, scene.inertia
    w = scene.drive.speed
    st = _state(theta, scene, state)
    gravity = np.array([0.0, -m.gravity])
    alpha_fg = w * w * st.dd_theta_fg
    alpha_ef = w * w * st.dd_theta_ef
    inertial = m.rod_mass * (w * w * st.dd_rod_com - gravity)  # m4 (a_C4 - g)
    f_t = sector_group_inertia(scene) * alpha_fg / g.l_fg
    d = st.point_f - st.point_e
    tangent, radial = _normal(st.theta_fg), _unit(st.theta_fg)
    rhs = -0.5 * _cross(d, inertial) - m.rod_inertia * alpha_ef - f_t * _cross(d, tangent)
    f_r = rhs / _cross(d, radial)
    f_s = f_t[..., None] * tangent + f_r[..., None] * radial
    return inertial + f_s, f_s


def ideal_pin_loads(scene: Scene, joint: str, samples: int = SAMPLES) -> PinLoads:
    """:class:`PinLoads` of pin ``joint`` ("e" or "f") over one revolution of the ideal mechanism."""
    theta = np.arange(samples) * (2.0 * np.pi / samples)
    st = linkage_state(theta, scene.geometry, scene.inertia.rocker_com)  # one linkage solve for all three
    f_e, f_s = pin_forces(theta, scene, st)
    if joint == "e":
        force, radius = np.hypot(*f_e.T), scene.joint.journal_radius
        mass = reflected_mass_e(theta, scene, st)
    else:
        force, radius = np.hypot(*f_s.T), scene.joint_f.journal_radius
        mass = np.full(theta.size, reflected_mass_f(scene))
    return PinLoads(theta, force, sliding_speed(theta, scene, joint, radius, st), mass)


def _state(theta: np.ndarray, scene: Scene, state):
    """``state`` when given, else the scene's :func:`linkage_state` at ``theta``."""
    return linkage_state(theta, scene.geometry, scene.inertia.rocker_com) if state is None else state


def sliding_speed(theta: np.ndarray, scene: Scene, joint: str, radius: float, state=None) -> np.ndarray:
    """R_j abs(omega_rel) of the ideal mechanism at crank angles ``theta``, m/s: rod against rocker at E,
    rod against sector at F; ``state`` as in :func:`reflected_mass_e`."""
    st = _state(theta, scene, state)
    other = st.d_phi if joint == "e" else st.d_theta_fg
    return radius * scene.drive.speed * np.abs(st.d_theta_ef - other)


# Grid of :func:`sliding_speed_at`: the ideal sliding speed is periodic in theta and smooth, so a run's
# thousands of step angles read it by linear interpolation on this grid (0.05 deg) instead of solving the
# linkage at each (the after-run checks of 10 revolutions: 54 000 angles, a quarter of the reference
# engine's run time).  Error of the interpolation on the reference scene and the loom: below 2e-6 of the
# peak sliding speed (measured 1.6e-7 on both, tests/test_design_checks.py).
SLIDING_GRID = 7200


def sliding_speed_at(theta: np.ndarray | tuple, scene: Scene, joint: str, radius: float) -> np.ndarray | tuple:
    """:func:`sliding_speed` at any crank angles theta (rad), interpolated on a grid of one revolution;
    ``theta`` a tuple of arrays reads them all from one grid (a tuple of results)."""
    grid = np.arange(SLIDING_GRID + 1) * (2.0 * np.pi / SLIDING_GRID)
    table = sliding_speed(grid, scene, joint, radius)
    if isinstance(theta, tuple):
        return tuple(np.interp(np.mod(t, 2.0 * np.pi), grid, table) for t in theta)
    return np.interp(np.mod(theta, 2.0 * np.pi), grid, table)
