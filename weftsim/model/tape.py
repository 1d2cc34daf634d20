"""The tape's Ritz matrices, its block of the kernel's parameter array, closed forms and its initial state.

:func:`ritz_matrices` integrates the products of the Ritz functions phi_i(eta) = (1 - eta) P_i(2 eta - 1)
of :mod:`weftsim.physics.tape` (P_i the Legendre polynomials) by Gauss-Legendre quadrature, exact for these
polynomials.  :func:`first_frequency` is the textbook closed form of a bar of mass M = mu lambda clamped at
one end with a mass m at the other: beta lambda tan(beta lambda) = M / m, omega = beta sqrt(E / rho)
(e.g. Blevins, Formulas for Natural Frequency and Mode Shape, table of bars with a tip mass), the check of the
Ritz model and the channel ``tape_frequency_hz``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np
from numpy.polynomial import Polynomial
from numpy.polynomial import legendre

from weftsim.input.params import RapierTape, Scene
from weftsim.physics import tape as kt

# Quadrature points: exact for the products of two Ritz functions of degree <= 8 and their derivatives.
_GAUSS_POINTS = 24



def tape_of(scene: Scene) -> RapierTape:
    """The scene's ``[rapier_tape]`` (ValueError for a scene without one: a rigid rapier has no tape model)."""
    if scene.rapier_tape is None:
        raise ValueError(f"scene {scene.name!r} has no [rapier_tape]: its rapier is rigid")
    return scene.rapier_tape

def stroke(scene: Scene) -> float:
    """The rapier's stroke (largest s of the ideal kinematics over a revolution), m."""
    from weftsim.mechanism.kinematics import rapier_stroke

    return rapier_stroke(scene.geometry)


@functools.lru_cache(maxsize=8)
def ritz_matrices(n: int) -> dict[str, np.ndarray]:
    """P, S, B, C, G, H (n x n) and p, h, d1, D1 (n) of the Ritz functions (:mod:`weftsim.physics.tape`)."""
    x, w = legendre.leggauss(_GAUSS_POINTS)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    funcs = [Polynomial([1.0, -1.0]) * legendre.Legendre.basis(i, domain=[0.0, 1.0]).convert(kind=Polynomial)
             for i in range(n)]
    f = np.array([p(x) for p in funcs])
    f1 = np.array([p.deriv()(x) for p in funcs])
    f2 = np.array([p.deriv(2)(x) for p in funcs])
    d = f1 + x * f2  # D_i = (eta phi_i')'
    out = {
        "P": (f * w) @ f.T, "S": (f1 * w) @ f1.T, "B": (f * x * w) @ f1.T, "C": (f1 * x * x * w) @ f1.T,
        "G": (f1 * w) @ d.T, "H": (d * w) @ d.T,
        "p": f @ w, "h": np.array([p(0.0) for p in funcs]), "d1": np.array([p.deriv()(1.0) for p in funcs]),
        "D1": np.array([p.deriv()(1.0) + p.deriv(2)(1.0) for p in funcs]),
    }
    for value in out.values():
        value.setflags(write=False)
    return out


def tape_block(scene: Scene, ratio: float, a0: float) -> np.ndarray:
    """The tape block of the kernel's parameter array (layout: :mod:`weftsim.physics.tape`).

    ``ratio``: ds/da = d5 d7 / d6 (m/rad); ``a0``: theta_FG at s = 0 (rad).
    """
    tape = tape_of(scene)
    n = tape.modes
    out = np.zeros(kt.block_size(n))
    out[kt.MODES], out[kt.MU], out[kt.EA] = n, tape.mass_per_length, tape.axial_stiffness
    out[kt.TAU], out[kt.HEAD], out[kt.LENGTH] = tape.damping_time, tape.head_mass, tape.length
    out[kt.FREE0], out[kt.RATIO], out[kt.A0] = tape.free_length, ratio, a0
    out[kt.GUIDE_MU], out[kt.GUIDE_G], out[kt.MASS] = tape.guide_friction_coefficient, scene.inertia.gravity, tape.mass
    m = ritz_matrices(n)
    k = kt.N_SCALARS
    for name in ("p", "h", "d1", "D1"):
        out[k:k + n] = m[name]
        k += n
    for name in ("P", "S", "B", "C", "G", "H"):
        out[k:k + n * n] = m[name].ravel()
        k += n * n
    return out


def first_frequency(tape: RapierTape, free_length) -> np.ndarray:
    """First axial natural frequency (Hz) of the free length(s) clamped at the wheel with the head at the end.

    beta L tan(beta L) = M / m (M = mu L, m the head), solved by Newton's method from the small-ratio
    start x^2 = r / (1 + r / 3); omega = beta sqrt(E / rho).  A head of mass 0 gives the bar's pi / 2.
    """
    lam = np.asarray(free_length, dtype=float)
    if tape.head_mass == 0.0:
        x = np.full(lam.shape, 0.5 * math.pi)
    else:
        r = tape.mass_per_length * lam / tape.head_mass
        x = np.sqrt(r / (1.0 + r / 3.0))
        x = np.minimum(x, 0.5 * math.pi - 1e-9)
        for _ in range(50):
            g = x * np.tan(x) - r
            dg = np.tan(x) + x / np.cos(x) ** 2
            x = np.clip(x - g / dg, 1e-12, 0.5 * math.pi - 1e-15)
    wave_speed = math.sqrt(tape.axial_modulus / tape.density)
    return x / lam * wave_speed / (2.0 * math.pi)


def ritz_frequencies(tape: RapierTape, free_length: float) -> np.ndarray:
    """Natural frequencies (Hz) of the Ritz model at a fixed free length (M_qq, K = EA S / lambda)."""
    from scipy.linalg import eigh

    m = ritz_matrices(tape.modes)
    mass = tape.mass_per_length * free_length * m["P"] + tape.head_mass * np.outer(m["h"], m["h"])
    stiffness = tape.axial_stiffness / free_length * m["S"]
    return np.sqrt(eigh(stiffness, mass, eigvals_only=True)) / (2.0 * math.pi)


def quasi_static(tape: RapierTape, free_length: float, wheel_acceleration: float) -> np.ndarray:
    """q of the tape at rest relative to a wheel accelerating at ``wheel_acceleration`` (m/s^2).

    With s' = q' = 0 the tape's equations (:mod:`weftsim.physics.tape`) ask M_sq s'' + M_qq q'' = -EA S q /
    lambda; q'' = 0 gives (EA S / lambda - mu s'' B) q = -(mu lambda p + m h) s''.
    """
    m = ritz_matrices(tape.modes)
    mu = tape.mass_per_length
    lhs = tape.axial_stiffness / free_length * m["S"] - mu * wheel_acceleration * m["B"]
    return np.linalg.solve(lhs, -(mu * free_length * m["p"] + tape.head_mass * m["h"]) * wheel_acceleration)


def rigid_equivalent(scene: Scene) -> Scene:
    """The scene with its tape and head as the rigid rapier's mass m8 (and no ``rapier_tape``)."""
    tape = tape_of(scene)
    return replace(scene, inertia=replace(scene.inertia, rapier_mass=tape.mass), rapier_tape=None)


def flexible_parameters(scene: Scene, base: np.ndarray) -> np.ndarray:
    """The kernel's parameter array of a flexible-tape scene from ``base``, the array of the same scene with a
    rapier of mass 0 (the tape and head move in the tape's equations): topology E_TAPE and the tape block."""
    from weftsim.physics import chain_f as kf
    from weftsim.mechanism.kinematics import linkage_state

    out = base[:kf.N_PARAMETERS].copy()
    out[kf.TOPOLOGY] = kf.E_TAPE
    a0 = float(linkage_state(0.0, scene.geometry, scene.inertia.rocker_com).theta_fg)
    return np.concatenate([out, tape_block(scene, scene.geometry.rapier_ratio, a0)])


def massless_rapier(scene: Scene) -> Scene:
    """The scene with the rigid rapier's mass m8 = 0 and no tape: the linkage the tape's equations drive."""
    return replace(scene, inertia=replace(scene.inertia, rapier_mass=0.0), rapier_tape=None)


def flexible_initial_state(scene: Scene, chain_state: np.ndarray, wheel_acceleration: float) -> np.ndarray:
    """[a, psi, q, a', psi', q', W3, D] at t = 0 from the chain's [a, psi, a', psi', W3, D].

    The journal starts centred with the ideal mechanism's velocities (docs/physics.md section 2), in free
    flight; the tape starts at rest on the wheel and in equilibrium with the wheel's acceleration there
    (:func:`quasi_static`), ``wheel_acceleration`` (m/s^2): that of the same start with the tape and head as the
    rigid rapier (:func:`rigid_equivalent`; :func:`weftsim.model.dynamics.initial_state` computes it).  So a
    stiff tape starts as the rigid rapier does, and the tape's vibration comes from the run (the start-up
    impact), not from its initial state.
    """
    tape = tape_of(scene)
    q0 = quasi_static(tape, tape.free_length, wheel_acceleration)
    n = tape.modes
    return np.concatenate([chain_state[:2], q0, chain_state[2:4], np.zeros(n), chain_state[4:6]])
