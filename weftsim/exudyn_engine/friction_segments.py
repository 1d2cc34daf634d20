"""Friction segments: Newton's iteration of the implicit kinematic tree on one smooth piece of the friction law.

The modified Coulomb law (docs/physics.md section 2; :func:`weftsim.physics.joint.friction_force`) is
piecewise linear in the sliding speed v_T::

    F_T / (mu F_N) = 0                          |v_T| <= v0        DEAD
                   = -(|v_T| - v0)/(v1 - v0) sign(v_T)   v0 < |v_T| < v1    RAMP
                   = -sign(v_T)                 |v_T| >= v1        SLIDE

with a slope mu F_N / (v1 - v0) ~ 1e8 N s/m on the ramp.  Newton's method on such a function cycles:
from a state on the flat SLIDE piece the Jacobian sees the inertia alone and jumps far onto the ramp
or beyond, from there back (measured on the loom, generalized-alpha, c = 0.5 mm, mu = 0.15: a 2-cycle
of the residual, 110.6 / 147.2, for all 25 iterations, at the first impact; the step then shrank to
1e-9 s, as the explicit solver's does).  The classic remedy (an active-set or "discontinuous"
iteration, which Exudyn runs through its post-Newton function) is used here:

1. Newton solves the step with the law frozen on one piece, extended beyond its own speed range:
   DEAD without friction; RAMP as the ramp's straight line beyond v1 (zero below v0, as the law);
   SLIDE as full Coulomb friction.  Each has fewer corners than the law, so Newton cycles less.
2. The post-Newton function reads v_T at the converged state; if it lies on another piece, that
   piece is frozen and Newton runs again from the state reached (Exudyn's discontinuous
   iteration, at most :data:`MAX_SWITCHES` times, then the step is halved).  A step is accepted
   only on the piece its own end state lies on, where the frozen and the true law are the same
   function: the accepted states solve the true law.

The pieces are made by setting the law's own parameters in the callback's copy (``prm``): DEAD
mu = 0; SLIDE v0 = -1, v1 = 0 (c_d = 1 at every speed); RAMP v1 = :data:`FAR` with mu scaled by
(FAR - v0) / (v1 - v0) (the same line, its saturation moved beyond any speed of the loom).  So the
force is still the kernel's :func:`weftsim.physics.chain.tree_joint_force` and nothing of the law is
written a second time.  Measured alternative: the RAMP's line continued below v0 down to v_T = 0 (a sum
of three kernel evaluations; the line must then jump at v_T = 0 by 2 mu F_N, as any odd function of v_T
not through the origin) took 2.3x the steps and 2.2x the Newton failures on the loom over a revolution.
"""

from __future__ import annotations

from weftsim.physics.joint import MU, V0, V1

DEAD, RAMP, SLIDE = 0, 1, 2
# The frozen ramp's saturation speed, m/s.  The frozen RAMP equals the law on v0 < |v_T| < v1 for any FAR > v1;
# FAR only has to lie beyond the speeds Newton's iterates reach, so that the frozen piece is a line there.
FAR = 1.0e3
# Switches of the frozen piece within one step before the step counts as failed (Exudyn then halves it).
# Measured on the loom (mu = 0.15, one revolution, c = 0.25 / 0.5 mm): of 13 790 / 10 129 accepted steps
# 96 / 98 % needed none, 495 / 182 one, 18 / 20 two or three; 61 / 11 met the limit (the pieces cycled)
# and were halved.
MAX_SWITCHES = 8


class FrictionSegments:
    """The piece of the friction law the tree's callback currently evaluates (module docstring).

    Parameters
    ----------
    force : callable
        The tree's callback (:func:`weftsim.exudyn_engine.callbacks.make_tree_force`); its parameter copy
        ``prm`` is written in place.
    """

    def __init__(self, force):
        self.prm = prm = force.prm
        self.mu, self.v0, self.v1 = float(prm[MU]), float(prm[V0]), float(prm[V1])
        self.segment = DEAD
        self.switches = 0
        self.freeze(DEAD)

    @staticmethod
    def _set(prm, mu: float, v0: float, v1: float) -> None:
        prm[MU], prm[V0], prm[V1] = mu, v0, v1

    def segment_of(self, v_t: float) -> int:
        """The piece of the true law at sliding speed v_t (the inequalities of the kernel's ramp)."""
        s = abs(v_t)
        if s <= self.v0:
            return DEAD
        return RAMP if s < self.v1 else SLIDE

    def freeze(self, segment: int) -> None:
        """Make the callback evaluate ``segment`` of the law at every speed."""
        mu, v0, v1 = self.mu, self.v0, self.v1
        if segment == DEAD:
            self._set(self.prm, 0.0, v0, v1)
        elif segment == RAMP:
            self._set(self.prm, mu * (FAR - v0) / (v1 - v0), v0, FAR)
        else:
            self._set(self.prm, mu, -1.0, 0.0)
        self.segment = segment

    def check(self, in_contact: bool, v_t: float) -> bool:
        """After Newton converged: True if the state is on the frozen piece (out of contact any piece
        is, friction is 0); else freeze the state's piece and return False (Newton must run again)."""
        if not in_contact:
            return True
        true = self.segment_of(v_t)
        if true == self.segment:
            return True
        self.freeze(true)
        self.switches += 1
        return False
