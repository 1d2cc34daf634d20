"""Continuous contact force laws of the clearance joint (docs/physics.md section 3).

Every law gives the normal contact force of a journal pressed into its bearing,

    F_N = max(0, K(delta) delta^n (1 + xi delta_dot / v_imp))   for delta > 0,
    F_N = 0                                                     for delta <= 0,

with penetration delta (m, positive in contact), penetration rate delta_dot (m/s,
positive while approaching), held impact velocity v_imp (m/s, the value of
delta_dot at contact onset), stiffness K (N/m^n, or a function of delta),
exponent n and dimensionless hysteresis factor xi.  The damping coefficient is
D = xi K delta^n / v_imp (N s/m, paper Eq. 19/23), so F_N = K delta^n + D delta_dot.

The impact velocity is supplied by the caller (the engines hold delta_dot at the
onset and floor it at ``ClearanceJoint.min_impact_velocity``); the numpy form raises
``ValueError`` where a non-positive value would be used, the scalar forms do not
check (speed).

Laws (chosen by name from :data:`LAWS`, built by :func:`make_law`):

==========================  ===================================  ====================
name                        stiffness K                          xi
==========================  ===================================  ====================
``lankarani_nikravesh``     K_LN (constant, Hertz/Johnson)       3 (1 - ce^2) / 4
``variable_kd``             K_BZ(delta) (Bai-Zhao)               3 (1 - ce^2) / 4
``flores``                  K_LN                                 8 (1 - ce) / (5 ce)
``hunt_crossley``           K_LN                                 3 (1 - ce) / 2
``gonthier``                K_LN                                 (1 - ce^2) / ce
``elastic_foundation``      L_b pi E* / (2 sqrt(2 (c + delta)))  3 (1 - ce^2) / 4
==========================  ===================================  ====================

with sigma_k = (1 - nu_k^2) / E_k, E* = 1 / (sigma_b + sigma_j) and

    K_LN = 4 / (3 (sigma_b + sigma_j)) sqrt(R_b R_j / (R_b - R_j))             N/m^1.5
    K_BZ(delta) = (pi/8) E* sqrt(2 delta (3c + 2 delta)^2 / (c + delta)^3)     "N/m^1.5"

K_BZ is d/d(delta) of Liu's per-unit-length elastic-foundation force, so it has the
units of a modulus (N/m^2); multiplying it by delta^1.5 (paper Eqs. 21-24) gives an
*empirical* law that is only meaningful in SI units.  ``elastic_foundation`` is the
dimensionally consistent cousin: Liu's force over the bearing length L_b,
F = L_b (pi/2) E* delta sqrt(delta / (2 (c + delta))), written here as K(delta)
delta^1.5 with K(delta) = L_b pi E* / (2 sqrt(2 (c + delta))).

Each law declares ``valid_restitution = (lo, hi)``: the range of ce for which a
single-mass impact returns the requested ce within 0.05 (absolute), lo <= ce <= hi.  For every law of
this family (damping proportional to the elastic force) the restored ce depends on xi
only, not on K(delta), mass or impact velocity: with W = integral F_el d(delta) and
u = delta_dot / v_imp, m v_imp^2 u du/dW = -(1 + xi u), whence the exact relation of
:func:`restored_restitution`.  Laws sharing xi (``lankarani_nikravesh``, ``variable_kd``,
``elastic_foundation``) therefore share their validity range.  Table of
restored - requested ce (from that relation, confirmed by direct integration in
``tests/test_contact.py``):

==========  =======  =======  =======  =======  =======  =======
ce          0.1      0.3      0.5      0.7      0.8      0.9
==========  =======  =======  =======  =======  =======  =======
LN/BZ/EF    +0.565   +0.384   +0.225   +0.096   +0.047   +0.013
flores      -0.031   -0.044   -0.030   -0.017   -0.011   -0.006
hunt_c.     +0.416   +0.281   +0.163   +0.068   +0.033   +0.009
gonthier    +0.001   +0.004   -0.012   -0.030   -0.032   -0.024
==========  =======  =======  =======  =======  =======  =======

Each law also declares ``valid_penetration_ratio``, the largest delta / c its elastic force is
derived for, and ``penetration_basis``, why: 0.1 for the Hertz-based laws (a narrow contact),
None for the conformal ``variable_kd`` and ``elastic_foundation`` (docs/plausibility.md).

Sources: Lankarani & Nikravesh, J. Mech. Des. 112 (1990); Hunt & Crossley,
J. Appl. Mech. 42 (1975); Gonthier et al., Multibody Syst. Dyn. 11 (2004); Flores
et al., Mech. Mach. Theory 46 (2011); Bai & Zhao, Int. J. Non-Linear Mech. 48
(2013); Liu, Zhang & Yang, Mech. Mach. Theory 42 (2007); Li et al. (2020), Eqs. 14-24;
Ambrosio (2003) for the modified Coulomb friction.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, ClassVar

import numpy as np

from numba import njit

from weftsim.joint.exact_damping import EXACT_HYSTERESIS
from weftsim.physics import laws as kernel
from weftsim.physics.python import python_form
from weftsim.input.params import ClearanceJoint

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

ScalarLaw = Callable[[float, float, float], float]


# Which law function _map_law evaluates (a number, not a function argument: numba compiles a function
# passed as an argument again in every process, ~0.2 s; this loop loads from its cache in ~5 ms).
_STIFFNESS, _ELASTIC_FORCE, _ELASTIC_ENERGY = 0, 1, 2
_LAW_FUNCTIONS = {kernel.stiffness: _STIFFNESS, kernel.elastic_force: _ELASTIC_FORCE,
                  kernel.elastic_energy: _ELASTIC_ENERGY}  # fmt: skip


@njit(cache=True, error_model="numpy")
def _map_law(which, kind, coef, clearance, delta, out):
    for i in range(delta.size):
        if which == _STIFFNESS:
            out[i] = kernel.stiffness(kind, coef, clearance, delta[i])
        elif which == _ELASTIC_FORCE:
            out[i] = kernel.elastic_force(kind, coef, clearance, delta[i])
        else:
            out[i] = kernel.elastic_energy(kind, coef, clearance, delta[i])


@njit(cache=True, error_model="numpy")
def _map_normal_force(kind, coef, clearance, xi, delta, rate, impact_velocity, out):
    for i in range(delta.size):
        out[i] = kernel.normal_force(kind, coef, clearance, xi, delta[i], rate[i], impact_velocity[i])


# Arrays shorter than this are evaluated by the kernel's plain-Python form (~1 us per element): the
# compiled loops load from numba's cache in ~5 ms once numba is set up in the process (an engine run
# has done that), but the first compiled call of a process costs ~0.3 s.  Measured: a 10-revolution
# run's 69 000 steps took 40-80 ms in plain Python against ~1 ms compiled.
_COMPILED_FROM = 2_000


def _law_array(fn, kind, coef, clearance, penetration):
    """``fn`` of :mod:`weftsim.physics.laws` at every element of ``penetration``."""
    delta = np.asarray(penetration, dtype=float)
    flat = np.ascontiguousarray(delta).ravel()
    if flat.size < _COMPILED_FROM:
        form = python_form(fn)
        out = np.fromiter((form(kind, coef, clearance, d) for d in flat.tolist()), float, flat.size)
    else:
        out = np.empty(flat.size)
        _map_law(_LAW_FUNCTIONS[fn], kind, coef, clearance, flat, out)
    return out.reshape(delta.shape)[()]


def lankarani_nikravesh_stiffness(joint: ClearanceJoint) -> float:
    """K_LN = 4 / (3 (sigma_b + sigma_j)) sqrt(R_b R_j / (R_b - R_j)), N/m^1.5 (paper Eq. 17)."""
    if joint.clearance <= 0.0:
        raise ValueError(f"`clearance` must be > 0 for a contact law, got {joint.clearance}")
    r_b, r_j = joint.bearing_radius, joint.journal_radius
    return 4.0 / 3.0 * joint.effective_modulus * math.sqrt(r_b * r_j / (r_b - r_j))


def bai_zhao_stiffness(penetration: ArrayLike, clearance: float, effective_modulus: float) -> np.ndarray | float:
    """K_BZ(delta) = (pi/8) E* sqrt(2 delta (3c + 2 delta)^2 / (c + delta)^3) (Bai & Zhao 2013).

    Empirical SI stiffness (N/m^2 dimensionally, used as N/m^1.5); 0 for delta <= 0.
    """
    return _law_array(kernel.stiffness, kernel.LAW_VARIABLE_KD, math.pi / 8.0 * effective_modulus, clearance,
                      penetration)  # fmt: skip


def check_impact_velocity(delta: np.ndarray, impact_velocity: np.ndarray) -> None:
    """``ValueError`` where delta > 0 and the impact velocity is not > 0 (arrays, broadcast)."""
    bad = (delta > 0.0) & ~(impact_velocity > 0.0)
    if np.any(bad):
        v = np.broadcast_to(impact_velocity, bad.shape)[bad].ravel()[0]
        raise ValueError(
            f"`impact_velocity` must be > 0 where penetration > 0 (the engines floor it at "
            f"ClearanceJoint.min_impact_velocity), got {v}"
        )


# The conformal laws' elastic force is Liu's elastic foundation (Liu, Zhang & Yang, Mech. Mach. Theory 42,
# 2007): radial springs over the whole arc on which the gap c - e cos(theta) has closed, cos(theta_c) =
# c / (c + delta), written for small clearances and large loads, where that arc is wide.  Its force
# F = L_b (pi/2) E* delta sin(theta_c / 2) holds for any arc below the half circle, which no finite delta
# reaches: the clearance sets no bound.  What bounds it is the material (small strains, no yield): the
# Hertz pressure against yield and the run's limits.max_penetration_ratio of the journal radius.
CONFORMAL_BASIS = ("the elastic-foundation force (Liu, Zhang & Yang 2007) is written for the wide arc of a conformal "
                   "contact at small clearance and large load: no bound on delta / c")


@dataclass(frozen=True)
class _Law:
    """Common part of all laws: F_N = max(0, K(delta) delta^n (1 + xi delta_dot / v_imp)), n = 1.5.

    Subclasses define ``kind`` (a law id of :mod:`weftsim.physics.laws`), ``coefficient``
    (its ``coef``) and ``hysteresis_factor``; the arithmetic is that of :mod:`weftsim.physics.laws`.
    """

    hysteresis: float  # xi, dimensionless
    restitution: float  # ce the hysteresis factor was built from

    name: ClassVar[str] = ""
    kind: ClassVar[int] = kernel.LAW_CONSTANT
    exponent: ClassVar[float] = 1.5
    valid_restitution: ClassVar[tuple[float, float]] = (0.0, 1.0)
    # Largest penetration / clearance the law's elastic force is derived for (None: no bound from the
    # clearance), and why.  The Hertz-based laws: Hertz's line contact assumes a contact width small
    # against the radii; two conforming cylinders at approach delta overlap over a half-width of about
    # R_j sqrt(2 delta / c), 0.45 R_j (an arc of +-25 deg) at delta = c / 10 (Johnson, Contact Mechanics,
    # 1985, section 4.3; Pereira, Ramalho & Ambrosio, Nonlinear Dyn. 63, 2011, on the validity domain of
    # Hertz-based cylinder laws in conformal contact at low clearance).
    valid_penetration_ratio: ClassVar[float | None] = 0.1
    penetration_basis: ClassVar[str] = ("Hertz's contact assumes a contact width small against the radii (Johnson "
                                         "1985, 4.3): at delta = c/10 the overlap spans +-25 deg of the pin")

    @staticmethod
    def hysteresis_factor(restitution: float) -> float:
        """xi(ce) of Lankarani-Nikravesh, 3 (1 - ce^2) / 4 (paper Eq. 16)."""
        return 0.75 * (1.0 - restitution**2)

    @property
    def coefficient(self) -> float:
        raise NotImplementedError

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        """(kind, coef, clearance, xi): the law's numbers for :mod:`weftsim.physics.laws`."""
        return self.kind, self.coefficient, getattr(self, "clearance", 0.0), self.hysteresis

    def stiffness(self, penetration: ArrayLike) -> np.ndarray | float:
        """K(delta), N/m^1.5 (at delta <= 0 the value at 0)."""
        kind, coef, c, _ = self.parameters
        return _law_array(kernel.stiffness, kind, coef, c, penetration)

    def elastic_force(self, penetration: ArrayLike) -> np.ndarray | float:
        """F_el = K(delta) delta^1.5 for delta > 0, else 0, N."""
        kind, coef, c, _ = self.parameters
        return _law_array(kernel.elastic_force, kind, coef, c, penetration)

    def elastic_energy(self, penetration: ArrayLike) -> np.ndarray | float:
        """W = integral_0^delta F_el, J (0 for delta <= 0); closed forms in :func:`weftsim.physics.laws.elastic_energy`."""
        kind, coef, c, _ = self.parameters
        return _law_array(kernel.elastic_energy, kind, coef, c, penetration)

    def damping(self, penetration: ArrayLike, impact_velocity: ArrayLike) -> np.ndarray | float:
        """D = xi K(delta) delta^1.5 / v_imp, N s/m (paper Eqs. 19, 23)."""
        return self.hysteresis * self.elastic_force(penetration) / np.asarray(impact_velocity, dtype=float)

    def normal_force(self, penetration: ArrayLike, penetration_rate: ArrayLike,
                     impact_velocity: ArrayLike) -> np.ndarray | float:
        """F_N = max(0, K delta^1.5 (1 + xi delta_dot / v_imp)) for delta > 0, else 0, N.

        Parameters (broadcast together)
        ----------
        penetration : array_like
            delta = |e| - c, m.
        penetration_rate : array_like
            delta_dot = e_dot . n, m/s, positive while approaching.
        impact_velocity : array_like
            Held delta_dot at contact onset, m/s, floored by the caller; must be > 0
            wherever delta > 0 (else ``ValueError``).
        """
        d = np.asarray(penetration, dtype=float)
        v = np.asarray(impact_velocity, dtype=float)
        check_impact_velocity(d, v)
        d, rate, v = np.broadcast_arrays(d, np.asarray(penetration_rate, dtype=float), np.where(v > 0.0, v, 1.0))
        flat = [np.ascontiguousarray(x).ravel() for x in (d, rate, v)]
        d_flat, rate_flat, v_flat = flat
        if d.size < _COMPILED_FROM:
            form = functools.partial(python_form(kernel.normal_force), *self.parameters)
            out = np.fromiter((form(*row) for row in zip(*(x.tolist() for x in flat))), float, d.size)
        else:
            out = np.empty(d.size)
            _map_normal_force(*self.parameters, d_flat, rate_flat, v_flat, out)
        return out.reshape(d.shape)[()]

    def scalar(self) -> ScalarLaw:
        """F_N(delta, delta_dot, v_imp), float -> float, in plain Python (the kernel's source)."""
        return functools.partial(python_form(kernel.normal_force), *self.parameters)

    def numba(self) -> ScalarLaw:
        """F_N(delta, delta_dot, v_imp) compiled with ``numba.njit`` around the kernel.

        Compiled once per distinct law (cached); the first call costs ~0.5 s of compilation.
        """
        return _jit(self)

    @classmethod
    def from_joint(cls, joint: ClearanceJoint) -> "_Law":
        """The law of ``joint`` (restitution, clearance, radii, materials, bearing length; the joint
        checked them when it was built, :func:`weftsim.input.params.joint_problem`)."""
        ce = joint.restitution
        if joint.clearance <= 0.0:
            raise ValueError(f"`clearance` must be > 0 for a contact law (0 is the ideal joint), "
                             f"got {joint.clearance}")
        return cls(hysteresis=cls.hysteresis_factor(ce), restitution=ce, **cls._parameters(joint))

    @staticmethod
    def _parameters(joint: ClearanceJoint) -> dict:
        raise NotImplementedError


@functools.lru_cache(maxsize=32)
def _jit(law: _Law) -> ScalarLaw:
    import numba

    kind, coef, c, xi = law.parameters
    normal_force = kernel.normal_force

    @numba.njit(cache=False)
    def scalar_law(delta, delta_dot, impact_velocity):
        return normal_force(kind, coef, c, xi, delta, delta_dot, impact_velocity)

    return scalar_law


@dataclass(frozen=True)
class _ConstantStiffnessLaw(_Law):
    """Law with constant stiffness K = K_LN; subclasses only change xi(ce)."""

    stiffness_constant: float = 0.0  # K, N/m^1.5

    @property
    def coefficient(self) -> float:
        """k = K_LN, N/m^1.5."""
        return self.stiffness_constant

    @staticmethod
    def _parameters(joint: ClearanceJoint) -> dict:
        return {"stiffness_constant": lankarani_nikravesh_stiffness(joint)}


@dataclass(frozen=True)
class LankaraniNikravesh(_ConstantStiffnessLaw):
    """Lankarani & Nikravesh (1990), paper Eq. 20: K_LN, xi = 3 (1 - ce^2) / 4.

    Derived for ce -> 1 (energy loss small against the elastic energy): a single-mass
    impact gives back 0.913 for ce = 0.9, 0.847 for 0.8, but 0.725 for 0.5 and 0.684
    for 0.3, so it is declared valid for ce >= 0.8 only (the paper notes the same limit).
    """

    name: ClassVar[str] = "lankarani_nikravesh"
    valid_restitution: ClassVar[tuple[float, float]] = (0.8, 1.0)


@dataclass(frozen=True)
class Flores(_ConstantStiffnessLaw):
    """Flores et al. (2011): K_LN, xi = 8 (1 - ce) / (5 ce); meant for any ce in (0, 1].

    Restored ce is slightly low everywhere, worst -0.045 near ce = 0.25 (0.256 for 0.3).
    """

    name: ClassVar[str] = "flores"
    valid_restitution: ClassVar[tuple[float, float]] = (0.0, 1.0)

    @staticmethod
    def hysteresis_factor(restitution: float) -> float:
        """xi = 8 (1 - ce) / (5 ce)."""
        return 8.0 * (1.0 - restitution) / (5.0 * restitution)


@dataclass(frozen=True)
class HuntCrossley(_ConstantStiffnessLaw):
    """Hunt & Crossley (1975): K_LN, xi = 3 (1 - ce) / 2; derived for ce -> 1.

    Restored ce: 0.909 for 0.9, 0.799 for 0.75, 0.663 for 0.5: valid for ce >= 0.75.
    """

    name: ClassVar[str] = "hunt_crossley"
    valid_restitution: ClassVar[tuple[float, float]] = (0.75, 1.0)

    @staticmethod
    def hysteresis_factor(restitution: float) -> float:
        """xi = 3 (1 - ce) / 2."""
        return 1.5 * (1.0 - restitution)


@dataclass(frozen=True)
class Gonthier(_ConstantStiffnessLaw):
    """Gonthier et al. (2004): K_LN, xi = (1 - ce^2) / ce.

    Restored ce within 0.033 of the requested one over the whole range (worst near
    ce = 0.75-0.8, e.g. 0.876 for 0.9; 0.304 for 0.3): valid for any ce.
    """

    name: ClassVar[str] = "gonthier"
    valid_restitution: ClassVar[tuple[float, float]] = (0.0, 1.0)

    @staticmethod
    def hysteresis_factor(restitution: float) -> float:
        """xi = (1 - ce^2) / ce."""
        return (1.0 - restitution**2) / restitution


@dataclass(frozen=True)
class VariableKD(_Law):
    """The paper's law (Eqs. 21-24, as restored): K_BZ(delta) delta^1.5 (1 + xi delta_dot / v_imp).

    K_BZ(delta) = a sqrt(2 delta (3c + 2 delta)^2 / (c + delta)^3), a = (pi/8) E*, so
    F_el = a sqrt(2) c^1.5 x^2 (3 + 2x) / (1 + x)^1.5 with x = delta / c.  Empirical in SI
    units (see module docstring).  xi is that of Lankarani-Nikravesh, derived for a constant
    K, but the restored ce depends on xi only (module docstring), so it is exactly that of
    Lankarani-Nikravesh: valid for ce >= 0.8.
    """

    clearance: float = 0.0  # c, m
    modulus_factor: float = 0.0  # a = (pi/8) E*, Pa

    name: ClassVar[str] = "variable_kd"
    valid_restitution: ClassVar[tuple[float, float]] = (0.8, 1.0)
    valid_penetration_ratio: ClassVar[float | None] = None
    penetration_basis: ClassVar[str] = CONFORMAL_BASIS

    kind: ClassVar[int] = kernel.LAW_VARIABLE_KD

    @property
    def coefficient(self) -> float:
        """a = (pi/8) E*, Pa."""
        return self.modulus_factor

    @staticmethod
    def _parameters(joint: ClearanceJoint) -> dict:
        return {"clearance": joint.clearance, "modulus_factor": math.pi / 8.0 * joint.effective_modulus}


@dataclass(frozen=True)
class ElasticFoundation(_Law):
    """Liu, Zhang & Yang (2007) improved elastic foundation over the bearing length L_b.

    F_el = L_b (pi/2) E* delta sqrt(delta / (2 (c + delta))) = K(delta) delta^1.5 with
    K(delta) = b / sqrt(2 (c + delta)), b = L_b pi E* / 2 (N/m, so K is N/m^1.5).  Damping
    with xi of Lankarani-Nikravesh (a choice of ours; the source is purely elastic), hence
    the same restored ce and validity (ce >= 0.8) as Lankarani-Nikravesh.
    """

    clearance: float = 0.0  # c, m
    length_modulus: float = 0.0  # b = L_b (pi/2) E*, N/m

    name: ClassVar[str] = "elastic_foundation"
    valid_restitution: ClassVar[tuple[float, float]] = (0.8, 1.0)
    valid_penetration_ratio: ClassVar[float | None] = None
    penetration_basis: ClassVar[str] = CONFORMAL_BASIS

    kind: ClassVar[int] = kernel.LAW_ELASTIC_FOUNDATION

    @property
    def coefficient(self) -> float:
        """b = L_b (pi/2) E*, N/m."""
        return self.length_modulus

    @staticmethod
    def _parameters(joint: ClearanceJoint) -> dict:
        if joint.bearing_length <= 0.0:
            raise ValueError(f"`bearing_length` must be > 0, got {joint.bearing_length}")
        return {"clearance": joint.clearance,
                "length_modulus": joint.bearing_length * math.pi / 2.0 * joint.effective_modulus}


EXACT_RESTITUTION_FLOOR = 0.05


def exact_hysteresis(restitution: float) -> float:
    """xi whose single-mass impact returns exactly ``restitution`` (the inverse of :func:`restored_restitution`).

    For every law of the family F_N = F_el(delta) (1 + xi delta_dot / v_imp) the restored ce solves
    phi(-xi ce) = phi(xi), phi(z) = z - ln(1 + z), whatever F_el (:func:`restored_restitution`); here that
    equation is solved for xi at the requested ce (0 < ce <= 1), so the law restores ce to solver precision
    over the whole range (Lankarani-Nikravesh's 3 (1 - ce^2) / 4 is its first-order form as ce -> 1).
    Below ce = :data:`EXACT_RESTITUTION_FLOOR` the root sits closer to xi = 1 / ce than a double resolves
    (1 - xi ce = 1.6e-8 at ce = 0.05, ~1e-21 at 0.02), so such a ce is refused with one line.  The roots of the
    round restitutions 0.05, 0.10, ..., 0.95 are stored (:mod:`weftsim.joint.exact_damping`, the solver's values
    to the last bit); any other ce is solved by :func:`solve_exact_hysteresis`.
    """
    if not EXACT_RESTITUTION_FLOOR <= restitution <= 1.0:
        raise ValueError(f"`restitution` must be in [{EXACT_RESTITUTION_FLOOR}, 1] for the cylindrical law's exact "
                         f"damping, got {restitution}")
    if restitution == 1.0:
        return 0.0
    stored = EXACT_HYSTERESIS.get(restitution)
    return solve_exact_hysteresis(restitution) if stored is None else stored


def solve_exact_hysteresis(ce: float) -> float:
    """The root xi > 0 of phi(-xi ce) = phi(xi) for 0.05 <= ce < 1 (:func:`exact_hysteresis`), by scipy's brentq
    at rtol 1e-15 (imported here, when called: ``scipy.optimize`` costs ~0.35 s of CPU to import)."""
    from scipy.optimize import brentq

    # phi(-xi ce) - phi(xi) = -(1 - ce^2) xi^2 / 2 + (1 + ce^3) xi^3 / 3 + ... < 0 below 1.5 (1 - ce^2) / (1 + ce^3),
    # and -> +inf as xi ce -> 1: the root xi > 0 (not the trivial xi = 0) lies between.
    lo = 0.1 * (1.0 - ce * ce)
    hi = (1.0 / ce) * (1.0 - 1e-15)
    return brentq(lambda xi: _excess_over_log(-xi * ce) - _excess_over_log(xi), lo, hi, xtol=1e-300, rtol=1e-15)


@dataclass(frozen=True)
class Cylindrical(_Law):
    """The conformal pin in its bushing, fitted to a plane-strain finite-element model (issue 37).

    F_el = k delta^n, a power law in the approach delta (the multibody penetration ``|e| - c``), with

        k = L_b E* R^(1 - n) exp(k0 + k1 ln(c/R) + k2 ln(t/R)),    n = n0 + n1 ln(c/R) + n2 ln(t/R),

    R the pin's radius, c the clearance, t the bushing's wall to a rigid housing
    (``bushing_wall``), L_b the bushing's length and E* the joint's effective modulus.  The form is Pereira,
    Ramalho & Ambrosio's (Nonlinear Dyn. 63, 2011: k delta^n with n falling as the clearance grows, fitted to
    finite elements); their constants are for a bushing in a thick plate, and are 40-100 % too compliant
    for a 4 mm bronze wall on a steel eye (docs/clearance-joint.md, "The cylindrical law"), so the
    constants (:data:`CYLINDRICAL_FIT`) are refitted to :mod:`weftsim.studies.cylinder_fe` over
    1-50 kN on 30 mm, 0.02 <= c <= 0.25 mm and 2.5 <= t <= 6 mm at R = 15 mm, steel on aluminium
    bronze (scripts/cylinder_fe_check.py prints the fit and the check).  Continuous at onset (F = 0
    and dF/d delta = 0 at delta = 0 for n > 1).  Damping: xi of :func:`exact_hysteresis`, so a free
    impact restores the requested ce for any ce in (0, 1].
    """

    clearance: float = 0.0  # c, m
    stiffness_coefficient: float = 0.0  # k, N/m^n
    power: float = 1.5  # n

    name: ClassVar[str] = "cylindrical"
    valid_restitution: ClassVar[tuple[float, float]] = (EXACT_RESTITUTION_FLOOR, 1.0)
    valid_penetration_ratio: ClassVar[float | None] = None
    penetration_basis: ClassVar[str] = ("fitted to a plane-strain FE model of the conformal pin in its bushing "
                                         "(1-50 kN on 30 mm, arcs up to +-50 deg): no bound on delta / c")
    kind: ClassVar[int] = kernel.LAW_CYLINDRICAL

    hysteresis_factor = staticmethod(exact_hysteresis)

    @property
    def exponent(self) -> float:  # type: ignore[override]
        return self.power

    @property
    def coefficient(self) -> float:
        """k, N/m^n."""
        return self.stiffness_coefficient

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        """(kind, k, c, xi), the exponent n packed in kind (:func:`weftsim.physics.laws.cylindrical_kind`)."""
        return kernel.cylindrical_kind(self.power), self.stiffness_coefficient, self.clearance, self.hysteresis

    @staticmethod
    def _parameters(joint: ClearanceJoint) -> dict:
        if joint.bushing_wall is None:
            raise ValueError("the `cylindrical` law needs the bushing's wall to its housing "
                             "(joint_e.bushing_wall_mm, > 0)")
        k, n = cylindrical_fit(joint.journal_radius, joint.clearance, joint.bushing_wall,
                               joint.bearing_length, joint.effective_modulus)
        return {"clearance": joint.clearance, "stiffness_coefficient": k, "power": n}


# (k0, k1, k2, n0, n1, n2) of Cylindrical, fitted by scripts/cylinder_fe_check.py (least squares in ln F).
CYLINDRICAL_FIT = (-0.55645, -0.58399, -0.34812, 1.17208, -0.029507, -0.00074290)


def cylindrical_fit(radius: float, clearance: float, wall: float, length: float,
                    effective_modulus: float, fit: tuple = CYLINDRICAL_FIT) -> tuple[float, float]:
    """(k, n) of :class:`Cylindrical`: k = L E* R^(1 - n) exp(k0 + k1 ln rho + k2 ln tau), n = n0 + n1 ln rho
    + n2 ln tau, rho = c / R, tau = t / R (SI units; k in N/m^n)."""
    k0, k1, k2, n0, n1, n2 = fit
    lr, lt = math.log(clearance / radius), math.log(wall / radius)
    n = n0 + n1 * lr + n2 * lt
    return length * effective_modulus * radius ** (1.0 - n) * math.exp(k0 + k1 * lr + k2 * lt), n


LAWS: dict[str, type[_Law]] = {
    law.name: law
    for law in (LankaraniNikravesh, VariableKD, Flores, HuntCrossley, Gonthier, ElasticFoundation, Cylindrical)
}


def make_law(joint: ClearanceJoint) -> _Law:
    """Build the contact law named by ``joint.law`` from the joint's geometry and materials."""
    try:
        cls = LAWS[joint.law]
    except KeyError:
        raise ValueError(
            f"unknown contact law `law` = {joint.law!r}; allowed: {', '.join(sorted(LAWS))}"
        ) from None
    return cls.from_joint(joint)


def _excess_over_log(z: float) -> float:
    """phi(z) = z - log(1 + z) for z > -1, without cancellation near 0."""
    if abs(z) > 0.1:
        return z - math.log1p(z)
    total, term = 0.0, -z
    for k in range(2, 40):  # term = (-1)^k z^k; |z|^40 / 40 < 1e-41: far below round-off
        term *= -z
        total += term / k
    return total


def restored_restitution(hysteresis: float) -> float:
    """Coefficient of restitution actually produced by a law with hysteresis factor xi.

    For m delta_ddot = -F_el(delta) (1 + xi delta_dot / v_imp), with any elastic law
    F_el >= 0 and W = integral_0^delta F_el, u = delta_dot / v_imp obeys
    m v_imp^2 u du/dW = -(1 + xi u).  Integrating from u = 1 (W = 0) to u = 0 (W max)
    and back to u = -ce (W = 0) gives phi(-xi ce) = phi(xi), phi(z) = z - ln(1 + z),
    independent of K(delta), n, m and v_imp; ce < 1/xi always (the force never clamps).
    """
    if hysteresis < 0.0:
        raise ValueError(f"`hysteresis` must be >= 0, got {hysteresis}")
    if hysteresis == 0.0:
        return 1.0
    from scipy.optimize import brentq  # only this diagnostic needs scipy

    xi = hysteresis
    target = _excess_over_log(xi)
    hi = min(1.0, 1.0 / xi) * (1.0 - 1e-15)
    return brentq(lambda ce: _excess_over_log(-xi * ce) - target, 0.0, hi, xtol=1e-16, rtol=1e-15)


_friction_factor = python_form(kernel.friction_factor)
# Array form for analysis and tests (plain Python per element; the integrators call the kernel).
_FRICTION_FACTOR = np.vectorize(_friction_factor, otypes=[float])


def friction_factor(tangential_speed: ArrayLike, v0: float, v1: float) -> np.ndarray | float:
    """Dynamic correction factor c_d of the modified Coulomb law (Ambrosio 2003), in [0, 1].

    Piecewise linear in ``|v_T|`` as in Ambrosio's law::

        c_d = 0 for |v_T| <= v0,  (|v_T| - v0) / (v1 - v0) for v0 < |v_T| < v1,  1 for |v_T| >= v1.

    Parameters
    ----------
    tangential_speed : array_like
        Relative tangential velocity v_T (sign ignored), m/s.
    v0, v1 : float
        Ramp limits, m/s, 0 <= v0 < v1 (docs/physics.md section 2: 1e-4 and 2e-4).
    """
    if not 0.0 <= v0 < v1:
        raise ValueError(f"friction velocities must satisfy 0 <= v0 < v1, got v0={v0}, v1={v1}")
    return _FRICTION_FACTOR(tangential_speed, v0, v1)[()]


def friction_factor_scalar(tangential_speed: float, v0: float, v1: float) -> float:
    """:func:`friction_factor` of one float, in plain Python (the kernel's source; no checks)."""
    return _friction_factor(tangential_speed, v0, v1)
