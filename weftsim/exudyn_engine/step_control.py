"""Step-size control of generalized-alpha for the rigid-body model: large steps in free flight, small through impacts.

Exudyn's generalized-alpha has no error control of its own (its ``adaptiveStep`` only cuts the step
after a Newton failure).  This module adds one from two of its hooks:

- a post-Newton user function (``mbs.SetPostNewtonUserFunction``) sees each converged trial step and
  rejects it when its local error estimate exceeds the tolerance; Exudyn then repeats the step from
  the start-of-step state with the recommended smaller step;
- a post-step hook (accepted steps only) sets the size of the next step on the solver
  (``solver.it.currentStepSize``), shortened so that a step ends on every output sample.

Local error estimate (Zienkiewicz and Xie 1991, for the Newmark family, which contains
generalized-alpha): the displacement after one step differs from the exact solution through the
same start state by

    e = |beta - 1/6| h^2 |a(t + h) - a(t)|

with beta the Newmark parameter of the method (0.309 at spectral radius 0.8).  It is applied to the
point the impacts act on: the journal centre at E, whose acceleration is bounded from its body's
node (centre of mass of the rod, member 4: translation plus arm x angular acceleration; one cheap
call per step).  The bearing on the rocker follows the prescribed kinematics of members 1-3, which
change far more slowly.  In free flight a(t) varies with the mechanism's kinematics (the estimate
allows steps of up to one output sample, 0.5 deg); through an impact it jumps by F_N / m within
microseconds (it asks for microsecond steps); in a lasting, smoothly loaded contact it lets the
step grow again.  The new step follows the usual controller for
an error of order h^3 (Hairer, Norsett and Wanner, Solving ODEs I, section II.4)::

    h_new = h * min(GROWTH_MAX, max(SHRINK_MIN, SAFETY * (tol / e)^(1/3)))

clamped to [min_step, max_step]; a step whose estimate exceeds ``REJECT_FACTOR * tol`` is repeated
with that step.  The ideal joint does not use it (solver.py: a fixed crank-angle step).

A lubricated joint's film has a corner at its wall h_min = h_wall (:data:`weftsim.physics.lubricated.FILM_WALL_RATIO`
sigma): below it the film is held, so where an impact drives the journal through the wall the film force
peaks there, on a corner a step rarely ends on (the reference scene's start-up impact: 41 MN, above 90 % of it
for 0.22 us, rising 6.6 % per 0.01 sigma of h_min towards the wall and falling 2.3 % per 0.01 sigma past it).  A step that crosses the wall by more than :data:`CORNER_TOL` h_wall is
repeated up to the wall (:func:`film_corners`, the linear interpolation of h_min over the step), so a step ends on
it, as on a sample time: the corner's value is then a row of the run, as the reference engine's error control
finds it (peak within 0.4 % there at its default tolerance).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import exudyn as exu

from weftsim.exudyn_engine.clearance_joint import register_post_step

if TYPE_CHECKING:
    import numpy as np

    from weftsim.exudyn_engine.mechanism import MechanismModel
    from weftsim.input.params import Scene

# Controller constants (Hairer, Norsett and Wanner, section II.4): aim at 0.9 of the tolerance,
# never shrink below 0.2 or grow beyond 2x in one step (a step that grows faster meets an impact
# it has not seen coming with too large a step, and the rejection costs a whole Newton solve).
SAFETY = 0.9
SHRINK_MIN = 0.2
GROWTH_MAX = 2.0
# A step is repeated only when its estimate exceeds this multiple of the tolerance: between 1 and 2
# the next step is shortened instead (standard practice; a rejection costs a full Newton solve).
REJECT_FACTOR = 2.0
# Rejections report this error to Exudyn (compared with discontinuous.iterationTolerance = 1).
_REJECT = 2.0
_ACCEPT = 0.0
_NO_RECOMMENDATION = -1.0
_OVT = exu.OutputVariableType
# A step ends on a corner of the film (film_corners) when its h_min is within this fraction of the corner's: the
# film force changes by 1.66 times h_min's relative change towards the reference scene's wall (0.58 past it), so the
# peak is found within 0.2 %.
CORNER_TOL = 1e-3


class StepController:
    """Error-controlled step size of one generalized-alpha run (module docstring).

    Parameters
    ----------
    mbs : exudyn.MainSystem
        The assembled mechanism.
    solver : exudyn.MainSolverImplicitSecondOrder
        The solver that will run it (its step size is set between steps).
    node : exudyn NodeIndex
        The 2-D rigid-body node of the journal's body (the rod, member 4).
    arm : float
        Distance from that node (the body's centre of mass) to the journal centre, m.
    tolerance : float
        Local error tolerance on the eccentricity, m.
    min_step, max_step : float
        Step range, s.
    sample_period : float
        Output sample spacing, s: every sample time is a step end.
    newmark_beta : float
        beta of the generalized-alpha method in use.
    jump : callable, optional
        ``jump(a0, a1)``: bound of the change of the journal centre's acceleration, m/s^2, between two
        outputs ``Coordinates_tt`` of ``node``; default: the rigid-body node's (:meth:`error`).  The
        kinematic tree passes its own (:mod:`.tree_implicit`).
    gap : callable, optional
        ``gap(mbs)``: the joint's minimum film thickness h_min = c - abs(e) at the current (trial) state, m; with
        ``corners`` (film thicknesses, m: :func:`film_corners`) a step that crosses one ends on it (module
        docstring).
    """

    def __init__(self, mbs, solver, node, arm: float, tolerance: float, min_step: float, max_step: float,
                 sample_period: float, newmark_beta: float, jump=None, gap=None, corners: tuple = ()):
        self.mbs = mbs
        self.it = solver.it  # the solver's step data (a live reference: writes reach the solver)
        self.node = node
        self.arm = arm
        self.tolerance = tolerance
        self.min_step = min_step
        self.floor_misses = 0  # steps accepted at min_step with an estimate above REJECT_FACTOR * tolerance
        self.max_step = min(max_step, sample_period)
        self.sample_period = sample_period
        self.factor = abs(newmark_beta - 1.0 / 6.0)
        self.jump = jump
        self.gap = gap if corners else None
        self.corners = tuple(corners)
        self.gap_start: float | None = None  # h_min at the last accepted state (None: not yet known)
        self.gap_trial: float | None = None
        self.corner_steps = 0  # steps repeated to end on a corner of the film
        self.accel_start: np.ndarray | None = None  # relative acceleration at the last accepted state
        self.accel_trial: np.ndarray | None = None
        self.error_trial = 0.0
        self.next_step = self.max_step
        self.rejected = 0
        self.smallest = math.inf
        self.largest = 0.0

    @classmethod
    def for_mechanism(cls, mbs: exu.MainSystem, solver: exu.MainSolverImplicitSecondOrder, model: MechanismModel,
                      scene: Scene) -> "StepController":
        """The controller of a built mechanism (:func:`~weftsim.exudyn_engine.mechanism.build_mechanism`)
        under the scene's settings: tolerance ``exudyn_solver.local_error``, steps between
        ``limits.min_step`` and one output sample period."""
        s = scene.exudyn_solver
        period = scene.output.sample_angle / scene.drive.speed
        journal = mbs.GetMarker(model.marker_journal)["localPosition"]
        clearance = model.clearance
        corners = film_corners(scene.joint) if clearance is not None else ()

        def gap(mbs_: exu.MainSystem) -> float:
            assert clearance is not None  # gap is read only with the corners, which need a clearance
            return -clearance.state(mbs_)[0]

        return cls(mbs, solver, model.nodes["rod"], math.hypot(journal[0], journal[1]), s.local_error, scene.limits.min_step, period, period,
                   newmark_beta(s.spectral_radius), gap=gap, corners=corners)

    def acceleration(self) -> np.ndarray:
        """Acceleration (x, y, angular) of the journal's body in the current trial or accepted state."""
        return self.mbs.GetNodeOutput(self.node, _OVT.Coordinates_tt)

    def error(self, h: float, a1: np.ndarray) -> float:
        """Local error estimate of a step of size h ending with journal-body acceleration a1, m.

        |a1 - a0| of the journal point is bounded by that of the body's centre plus |r| times the
        change of its angular acceleration (r = centre to journal; the change of the centripetal
        term within a step is far smaller).
        """
        a0 = self.accel_start
        if a0 is None:  # post_step runs at t = 0, before any step's post-Newton call
            raise RuntimeError("StepController.error: no accepted state yet (post_step was not called at t = 0)")
        if self.jump is not None:
            return self.factor * h * h * self.jump(a0, a1)
        jump = math.hypot(a1[0] - a0[0], a1[1] - a0[1]) + self.arm * abs(a1[2] - a0[2])
        return self.factor * h * h * jump

    def proposal(self, h: float, error: float) -> float:
        """Next step after a step h with estimate ``error`` (controller of the module docstring)."""
        if error <= 0.0:
            ratio = GROWTH_MAX
        else:
            ratio = min(GROWTH_MAX, max(SHRINK_MIN, SAFETY * (self.tolerance / error) ** (1.0 / 3.0)))
        return min(self.max_step, max(self.min_step, h * ratio))

    def post_newton(self, mbs: exu.MainSystem, t: float) -> list[float]:
        """Exudyn post-Newton function: [error flag, recommended step] of the converged trial step."""
        h = self.it.currentStepSize
        a1 = self.acceleration()
        err = self.error(h, a1)
        if err > REJECT_FACTOR * self.tolerance and h > self.min_step * (1.0 + 1e-9):
            # Exudyn repeats the step with min(0.75 h, recommendation) from the start-of-step state.
            self.rejected += 1
            return [_REJECT, self.proposal(h, err)]
        if err > REJECT_FACTOR * self.tolerance:  # at the floor: accepted above the tolerance (the run's guard fails it)
            self.floor_misses += 1
        if self.gap is not None:
            g1 = self.gap(mbs)
            to_corner = self.corner_fraction(self.gap_start, g1)
            if to_corner is not None and h * to_corner >= self.min_step:
                self.corner_steps += 1
                return [_REJECT, h * to_corner]
            self.gap_trial = g1
        self.accel_trial, self.error_trial = a1, err
        return [_ACCEPT, _NO_RECOMMENDATION]

    def corner_fraction(self, g0: float | None, g1: float) -> float | None:
        """The fraction of the step from h_min = ``g0`` to ``g1`` that ends on a corner of the film it crosses
        (linear in h_min; the nearest to the start), or None: no corner crossed by more than CORNER_TOL of it."""
        if g0 is None:
            return None
        best = None
        for level in self.corners:
            tol = CORNER_TOL * level
            if (g0 - level) * (g1 - level) < 0.0 and abs(g0 - level) > tol and abs(g1 - level) > tol:
                fraction = (g0 - level) / (g0 - g1)
                best = fraction if best is None else min(best, fraction)
        return best

    def post_step(self, mbs: exu.MainSystem, t: float) -> bool:
        """After an accepted step (and once at t = 0): plan the next step, ending on the sample grid."""
        if t <= 0.0 or self.accel_trial is None:
            self.accel_start = self.acceleration()
            self.gap_start = self.gap(mbs) if self.gap is not None and t <= 0.0 else None
            h_next = self.next_step
        else:
            h = self.it.currentStepSize
            self.smallest = min(self.smallest, h)
            self.largest = max(self.largest, h)
            self.accel_start = self.accel_trial
            self.gap_start = self.gap_trial
            h_next = self.proposal(h, self.error_trial)
        self.accel_trial = self.gap_trial = None
        self.next_step = h_next
        self.it.currentStepSize = to_sample_grid(t, h_next, self.sample_period)
        return True

    def install(self) -> None:
        """Register both hooks on the system."""
        self.mbs.SetPostNewtonUserFunction(self.post_newton)
        register_post_step(self.mbs, self.post_step)

    def counters(self) -> dict:
        return {"rejected_error_steps": self.rejected, "corner_steps": self.corner_steps,
                "smallest_step_s": self.smallest if math.isfinite(self.smallest) else None,
                "largest_step_s": self.largest or None}  # fmt: skip


def film_corners(joint) -> tuple[float, ...]:
    """Film thicknesses h_min (m) where a lubricated joint's film force has a corner: its wall h_wall, below which
    the film is held (:func:`weftsim.physics.lubricated.film_at_floor`); none for a dry joint or one without oil."""
    from weftsim.physics.lubricated import FILM_WALL_RATIO

    lub = joint.lubrication
    if lub is None or not (lub.viscosity > 0.0 or lub.has_oil):
        return ()
    return (FILM_WALL_RATIO * lub.roughness,)


def newmark_beta(spectral_radius: float) -> float:
    """Newmark beta of generalized-alpha at spectral radius rho (Chung and Hulbert 1993; as in Exudyn).

    alpha_m = (2 rho - 1) / (rho + 1), alpha_f = rho / (rho + 1), beta = (1 - alpha_m + alpha_f)^2 / 4.
    """
    rho = spectral_radius
    alpha_m = (2.0 * rho - 1.0) / (rho + 1.0)
    alpha_f = rho / (rho + 1.0)
    return 0.25 * (1.0 - alpha_m + alpha_f) ** 2


def to_sample_grid(t: float, h: float, period: float) -> float:
    """Step from time t of at most h that does not cross the next sample time k * period.

    Within 1.2 h of the sample the step ends on it (a step up to 20 % longer than planned rather than
    a sliver); within 2 h the remainder is split in two equal steps.
    """
    k = math.floor(t / period * (1.0 + 1e-12)) + 1
    remaining = k * period - t
    if remaining <= period * 1e-9:  # t sits on a sample within round-off: aim at the next one
        remaining += period
    if remaining <= 1.2 * h:
        return remaining
    if remaining <= 2.0 * h:
        return 0.5 * remaining
    return h


def failure_reason(solver, scene: Scene) -> tuple[str, str]:
    """(failure kind, reason) from Exudyn's convergence flags after SolveSystem returned False (the
    generalized-alpha solver of the rigid-body model and of the implicit tree alike)."""
    conv = solver.conv
    if not math.isfinite(conv.residual):
        # Exudyn reports a NaN force (e.g. from a user function) as Newton non-convergence.
        return "non_finite", (f"the Newton residual is {conv.residual}: a force or the state became NaN or inf, "
                              f"and cutting the step down to limits.min_step_s = {scene.limits.min_step:.3g} s "
                              "did not help")  # fmt: skip
    if conv.massMatrixNotInvertible or conv.linearSolverFailed:
        return "singular", f"singular system matrix (equation {conv.linearSolverCausingRow})"
    if conv.newtonSolutionDiverged:
        return "newton", "Newton diverged"
    if conv.stepReductionFailed:
        return "newton", (f"Newton did not converge, even with the step cut down to limits.min_step_s = "
                          f"{scene.limits.min_step:.3g} s (step-size collapse)")  # fmt: skip
    return "newton", "Newton did not converge"
