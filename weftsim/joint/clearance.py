"""Planar revolute clearance joint: geometry, normal and friction force (docs/physics.md section 2).

Array forms of the joint's force for analysis and tests (Flores-Ambrosio formulation; the
one scalar definition is :mod:`weftsim.physics.joint`, which the engines call)::

             bearing (R_b), centre P_b
          .-----------.
        /     journal   \\            e = P_j - P_b        eccentricity vector, m
       |   P_b --e--> P_j|Q          n = e / |e|          contact normal (bearing -> journal)
        \\               /            t = (-n_y, n_x)     n turned +90 deg about +z
          '-----------'              delta = |e| - c      penetration, m (< 0: free flight)
                                     Q = P_b + R_b n      contact point (on both bodies)

- Penetration rate delta_dot = e_dot . n (m/s, positive while approaching).
- Normal force F_N = law.normal_force(delta, delta_dot, v_imp) >= 0 (:mod:`weftsim.joint.contact`).
  The engine holds the impact velocity: delta_dot at the contact onset, floored at
  ``joint.min_impact_velocity``, kept until separation and, under the default rule
  ``joint.impact_velocity_rule = "max_approach"``, raised to every larger approach rate since
  the onset.  This module applies that last part itself (:func:`effective_impact_velocity`):
  v_imp = max(held, delta_dot), so the damping term xi delta_dot / v_imp never exceeds xi even
  between the engine's updates of the held value.  In an isolated impact delta_dot only falls
  after the onset, so the rule gives the onset value of Lankarani & Nikravesh (1990) and every
  law keeps its restitution; in a driven lasting contact the approach rate can grow far beyond
  the onset value, and the onset-only rule (``"onset"``, kept for comparison with published
  results) then inflates the damping force without bound.
- Friction (modified Coulomb, Ambrosio 2003): on the journal, ``F_T = -mu c_d(|v_T|) F_N sign(v_T) t``,
  with v_T = (velocity of the journal's material point at Q - that of the bearing's) . t.
- Force on the journal f_j = -F_N n + F_T (pulls it back towards the bearing centre); on the
  bearing f_b = -f_j; both act at Q.  The normal part passes through P_b and P_j (``Q - P_j =
  (R_b - |e|) n``), so only friction has a moment about the centres:
  ``M_j = (R_b - |e|) F_T.t`` about P_j and ``M_b = -R_b F_T.t`` about P_b (N m, about +z).
- e = 0 (journal centred, the initial state) is free flight: zero force, n = 0, delta_dot = 0.

Sources: Flores & Ambrosio, Comput. Struct. 82 (2004); Li et al. (2020) Eqs. 1-13.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, NamedTuple

import numpy as np

from weftsim.joint.contact import check_impact_velocity
from weftsim.physics import hold
from weftsim.physics import joint as kernel_joint
from weftsim.physics.joint import joint_parameters
from weftsim.physics.python import python_form
from weftsim.input.params import ClearanceJoint

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from weftsim.joint.contact import _Law

# Array forms for analysis and tests, plain Python per element (the engines call the compiled kernel).
_EFFECTIVE_IMPACT_VELOCITY = np.vectorize(python_form(hold.effective_impact_velocity), otypes=[float])
# The clearance geometry, written once in the kernel (weftsim.physics.joint.contact_geometry).
_CONTACT_GEOMETRY = np.vectorize(python_form(kernel_joint.contact_geometry), otypes=[float] * 4)
_TANGENTIAL_VELOCITY = np.vectorize(python_form(kernel_joint.contact_tangential_velocity), otypes=[float])
# The joint's parameter array is passed whole to every element (excluded from broadcasting).
_CLEARANCE_FORCE = np.vectorize(python_form(kernel_joint.clearance_force), otypes=[float] * 8, excluded={0})


class ClearanceContact(NamedTuple):
    """Everything about one contact evaluation (arrays over the leading axes of ``ecc``).

    force_on_journal, force_on_bearing : (..., 2) N, acting at the contact point Q.
    moment_on_journal : N m about +z, about the journal centre P_j (friction only).
    moment_on_bearing : N m about +z, about the bearing centre P_b (friction only).
    normal_force : F_N >= 0, N.          friction_force : F_T . t on the journal, N.
    penetration : delta, m.              penetration_rate : delta_dot, m/s.
    normal : n (..., 2), 0 at e = 0.     contact_offset : Q - P_b = R_b n (..., 2), m.
    """

    force_on_journal: np.ndarray
    force_on_bearing: np.ndarray
    moment_on_journal: np.ndarray
    moment_on_bearing: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    penetration: np.ndarray
    penetration_rate: np.ndarray
    normal: np.ndarray
    contact_offset: np.ndarray


def contact_geometry(ecc: ArrayLike, ecc_rate: ArrayLike,
                     clearance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Penetration, its rate and the normal from the eccentricity (docs/physics.md section 2): the kernel's
    :func:`weftsim.physics.joint.contact_geometry` at every element.

    Parameters
    ----------
    ecc, ecc_rate : array_like (..., 2)
        e = P_j - P_b (m) and its time derivative (m/s), in-plane.
    clearance : float
        c = R_b - R_j, m.

    Returns
    -------
    penetration : (...,) delta = |e| - c, m.
    penetration_rate : (...,) delta_dot = e_dot . n, m/s (0 where e = 0).
    normal : (..., 2) n = e / |e| (0 where e = 0).
    """
    e = np.asarray(ecc, dtype=float)
    e_dot = np.asarray(ecc_rate, dtype=float)
    delta, rate, nx, ny = (np.asarray(v) for v in _CONTACT_GEOMETRY(e[..., 0], e[..., 1], e_dot[..., 0],
                                                                    e_dot[..., 1], clearance))
    return delta[()], rate[()], np.stack([nx, ny], axis=-1)


def tangential_velocity(ecc: ArrayLike, bearing_velocity: ArrayLike, bearing_angular_velocity: ArrayLike,
                        journal_velocity: ArrayLike, journal_angular_velocity: ArrayLike,
                        bearing_radius: float) -> np.ndarray:
    """Relative tangential velocity v_T of the contact points (journal relative to bearing), m/s.

    Both material points sit at Q = P_b + R_b n::

        v_Q,b = v_Pb + w_b R_b t,  v_Q,j = v_Pj + w_j (R_b - |e|) t, and
        v_T = (v_Q,j - v_Q,b) . t = (v_Pj - v_Pb) . t + w_j (R_b - |e|) - w_b R_b.

    0 where e = 0 (no normal, no contact).  The kernel's :func:`weftsim.physics.joint.tangential_velocity` at
    every element.

    Parameters
    ----------
    ecc : (..., 2) eccentricity e = P_j - P_b, m.
    bearing_velocity, journal_velocity : (..., 2) velocities of the centres P_b, P_j, m/s.
    bearing_angular_velocity, journal_angular_velocity : (...,) rad/s about +z.
    bearing_radius : float
        R_b, m.
    """
    e = np.asarray(ecc, dtype=float)
    dv = np.asarray(journal_velocity, dtype=float) - np.asarray(bearing_velocity, dtype=float)
    return _TANGENTIAL_VELOCITY(e[..., 0], e[..., 1], dv[..., 0], dv[..., 1], journal_angular_velocity,
                                bearing_angular_velocity, bearing_radius)[()]


def effective_impact_velocity(held: ArrayLike, penetration_rate: ArrayLike,
                              joint: ClearanceJoint) -> np.ndarray | float:
    """The impact velocity delta_dot^- of the damping term, m/s (arrays, broadcast).

    ``held``: the engine's held value (onset rate floored at v_min, raised at its updates);
    under ``"max_approach"`` the current approach rate raises it further, under ``"onset"`` not
    (:func:`weftsim.physics.hold.effective_impact_velocity`).
    """
    rule = joint.impact_velocity_rule == "max_approach"
    return _EFFECTIVE_IMPACT_VELOCITY(held, penetration_rate, rule)[()]


def clearance_contact(ecc: ArrayLike, ecc_rate: ArrayLike, rel_tangential_velocity: ArrayLike,
                      impact_velocity: ArrayLike, law: _Law, joint: ClearanceJoint) -> ClearanceContact:
    """Normal and friction force of the clearance joint, with moments (arrays, broadcast).

    :func:`weftsim.physics.joint.clearance_force` at every element.

    Parameters
    ----------
    ecc, ecc_rate : array_like (..., 2)
        Eccentricity e = P_j - P_b (m) and its rate (m/s).
    rel_tangential_velocity : array_like (...,)
        v_T, m/s: tangential component (along t) of the journal contact point's velocity
        relative to the bearing's (:func:`tangential_velocity`).  Ignored when mu = 0.
    impact_velocity : array_like (...,)
        Held, floored impact velocity, m/s (> 0 wherever delta > 0, else ``ValueError``); the
        joint's rule raises it (:func:`effective_impact_velocity`).
    law : contact law of :mod:`weftsim.joint.contact` (from ``make_law(joint)``).
    joint : ClearanceJoint
        Supplies c, R_b, mu, the friction ramp (v0, v1) and the impact-velocity rule.
    """
    delta, _, n = contact_geometry(ecc, ecc_rate, joint.clearance)
    check_impact_velocity(delta, np.asarray(impact_velocity, dtype=float))
    e = np.asarray(ecc, dtype=float)
    e_dot = np.asarray(ecc_rate, dtype=float)
    prm = joint_parameters(joint, law)
    fx, fy, f_n, f_t, delta, delta_dot, m_j, m_b = (np.asarray(v) for v in _CLEARANCE_FORCE(
        prm, e[..., 0], e[..., 1], e_dot[..., 0], e_dot[..., 1], rel_tangential_velocity, impact_velocity))
    force_j = np.stack([fx, fy], axis=-1)
    return ClearanceContact(
        force_on_journal=force_j,
        force_on_bearing=-force_j,
        moment_on_journal=m_j[()],
        moment_on_bearing=m_b[()],
        normal_force=f_n[()],
        friction_force=f_t[()],
        penetration=delta[()],
        penetration_rate=delta_dot[()],
        normal=n,
        contact_offset=joint.bearing_radius * n,
    )


def clearance_force(ecc: ArrayLike, ecc_rate: ArrayLike, rel_tangential_velocity: ArrayLike, impact_velocity: ArrayLike,
                    law: _Law, joint: ClearanceJoint) -> tuple[np.ndarray | float, ...]:
    """Force on the journal (..., 2) N, F_N (N), delta (m), delta_dot (m/s): the agreed short form.

    See :func:`clearance_contact` for parameters, moments and the force on the bearing (-force).
    """
    r = clearance_contact(ecc, ecc_rate, rel_tangential_velocity, impact_velocity, law, joint)
    return r.force_on_journal, r.normal_force, r.penetration, r.penetration_rate


ClearanceKernel = Callable[[float, float, float, float, float, float], tuple]


def make_clearance_kernel(law: _Law, joint: ClearanceJoint, jit: bool = False) -> ClearanceKernel:
    """Scalar form of :func:`clearance_contact` for inner loops.

    Returns ``kernel(ex, ey, ex_dot, ey_dot, v_t, v_imp) -> (fx, fy, F_N, delta, delta_dot,
    M_j, M_b)``: force on the journal (N), normal force, penetration (m) and its rate (m/s),
    friction moments about P_j and P_b (N m), from :func:`weftsim.physics.joint.clearance_force`
    (plain Python, or compiled with ``jit=True``), with the joint's impact-velocity rule applied
    to the held v_imp.  No argument checks: v_imp must be > 0 in contact.
    """
    prm = joint_parameters(joint, law)
    if jit:
        import numba

        force = kernel_joint.clearance_force

        @numba.njit(cache=False)
        def compiled(ex, ey, ex_dot, ey_dot, v_t, v_imp):
            fx, fy, f_n, _, delta, delta_dot, m_j, m_b = force(prm, ex, ey, ex_dot, ey_dot, v_t, v_imp)
            return fx, fy, f_n, delta, delta_dot, m_j, m_b

        return compiled
    python_force = python_form(kernel_joint.clearance_force)

    def kernel(ex: float, ey: float, ex_dot: float, ey_dot: float, v_t: float, v_imp: float):
        fx, fy, f_n, _, delta, delta_dot, m_j, m_b = python_force(prm, ex, ey, ex_dot, ey_dot, v_t, v_imp)
        return fx, fy, f_n, delta, delta_dot, m_j, m_b

    return kernel
