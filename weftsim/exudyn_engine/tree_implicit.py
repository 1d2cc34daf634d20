"""The kinematic tree on generalized-alpha: implicit steps with error control, for friction (issue 23).

With friction the explicit tree (:mod:`.tree_solve`, DOPRI5) steps at its stability limit, ~1e-9 s,
whenever the journal rides on the bearing with a sliding speed on the friction ramp (0.1-0.2 mm/s):
the ramp is a damper of mu F_N / (v1 - v0) ~ 1e8 N s/m on a rod of 0.6 kg.  An implicit method is
not bound by that time constant, and ``ObjectKinematicTree`` runs on Exudyn's generalized-alpha solver
(its Jacobian, velocity terms of the force callback included, numerically).  Three additions make it
work on this model:

- **error control**: Exudyn's generalized-alpha has none; :class:`weftsim.exudyn_engine.step_control.
  StepController` (the rigid-body model's) estimates the local error of the journal centre from the
  change of its acceleration over the step, here from the tree's joint accelerations::

      |a_P(t+h) - a_P(t)| <= L_FG |q0''(t+h) - q0''(t)| + L_EF |b''(t+h) - b''(t)|,  b = q0 + q1

  (the changes of the centripetal terms within a step are far smaller), and rejects and shortens or
  lengthens the step to ``solver.exudyn.local_error_m``;
- **friction segments** (:mod:`.friction_segments`): Newton solves each step on one smooth piece of
  the friction law; the post-Newton function switches the piece until the step's end state lies on
  it (else Newton cycles on the law's corners);
- the post-step bookkeeping of :class:`weftsim.exudyn_engine.tree.TreeModel` as on the explicit path
  (onset, held impact velocity, the force on the bearing), at the converged state.

Everything else (channels, guards, failures) is :mod:`.tree_solve`'s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import exudyn as exu

from weftsim.exudyn_engine import callbacks
from weftsim.exudyn_engine.clearance_joint import register_post_step
from weftsim.exudyn_engine.friction_segments import MAX_SWITCHES, FrictionSegments
from weftsim.exudyn_engine.selection import largest_step, tree_local_error
from weftsim.exudyn_engine.step_control import StepController, film_corners, newmark_beta, to_sample_grid

if TYPE_CHECKING:
    from weftsim.exudyn_engine.tree import TreeModel
    from weftsim.input.params import Scene

OVT = exu.OutputVariableType
# Newton: full (a fresh Jacobian each iteration: with friction the ramp's slope changes the Jacobian by
# 1e8 N s/m between pieces; modified Newton, also with a Jacobian per step, failed or took more calls) to
# this relative tolerance of the residual.  Measured over one revolution with friction: 1e-8, 1e-6, 1e-4
# took 175 000, 148 000 (stash reuse included), 143 000 force calls, with the same peaks to 6 digits at
# 1e-8 and 1e-6; 1e-4 moved the torque peak by 3e-5.
NEWTON_RELATIVE_TOLERANCE = 1e-6
# Dry friction without the power joints (tree_solve.power_sums), measured again on the loom (cylindrical law, one
# revolution, mu = 0.15, 3 December 2026): at 1e-6, 1e-5, 1e-4 267 590, 227 944, 158 296 force calls at
# c = 0.02 mm and 267 872, 217 767, 186 834 at 0.1 mm; at 1e-5 the contact force and acceleration maxima move by
# 4e-7 and 2.5e-5 and the 0.02 mm torque maximum comes 3.5e-4 from the converged 1 338.23 N m (1e-6: 9.5e-4), the
# energy residual over 3 revolutions 6.6e-6 of the largest kinetic energy (1e-6: 7.5e-6); 1e-4 moved the 0.1 mm
# maxima by 2.4e-2.  The film keeps 1e-6 (not measured at 1e-5).
FRICTION_NEWTON_RELATIVE_TOLERANCE = 1e-5
# Spectral radius at infinite frequency: 1, no numerical damping (generalized-alpha is then the trapezoidal
# Newmark rule).  The tree has no constraints, so no constraint torque needs the damping the rigid-body model
# takes for them (solver.exudyn.spectral_radius, 0.8), and any damping below 1 is energy the balance misses:
# one revolution with friction, c = 0.5 mm, 400 rpm, residual 2.3 J at 0.8, 0.23 J at 0.98, 0.03 J at 1
# (two revolutions; also the fastest, 2.35 s against 3.76 s at 0.8).
SPECTRAL_RADIUS = 1.0
# Newton iterations before Exudyn halves the step.  Converged steps took 1-5 (99.8 % of them; friction
# switches included) on the loom with friction; a cycling Newton never converges, and 25 (the default)
# made each failure cost five converged steps.  Force calls for one revolution of four scenes (c = 0.25,
# 0.5 mm; mu = 0.05, 0.15) at 4, 5, 6, 7, 8: 552 000, 532 000, 529 000, 548 000, 563 000.
NEWTON_MAX_ITERATIONS = 6
# Steps without lengthening after a Newton failure (TreeStepController).  Force calls over one revolution
# (c = 0.5 mm, mu = 0.15) with 4, 8, 15 held steps: 182 000, 148 000, 151 000; at Newton tolerance 1e-8, with
# 0, 8, 30: 354 000, 175 000, 282 000.
HOLD_STEPS = 8
# Post-Newton error that makes Exudyn run Newton again on the same step (its discontinuous iteration: above
# discontinuous.iterationTolerance = 1, with no recommended step): the friction piece was switched.
_REPEAT = 2.0


class TreeStepController(StepController):
    """:class:`StepController` that does not lengthen the step for :data:`HOLD_STEPS` steps after Newton
    failed and Exudyn halved it (the error estimate alone would double it again at once, into the same
    failure: measured on the loom with friction, heavy creeping contacts then failed Newton step after step)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.planned = self.next_step
        self.hold = 0
        self.newton_cut_steps = 0  # accepted steps that Exudyn had cut (once or more) after Newton failed

    def post_newton(self, mbs: exu.MainSystem, t: float) -> list[float]:
        out = super().post_newton(mbs, t)
        if out[0] > 0.0:  # rejected: Exudyn repeats with min(0.75 h, the recommendation)
            self.planned = min(0.75 * self.it.currentStepSize, out[1])
        return out

    def post_step(self, mbs: exu.MainSystem, t: float) -> bool:
        h = self.it.currentStepSize
        if t > 0.0 and h < self.planned * (1.0 - 1e-9):  # Exudyn cut the planned step: Newton failed
            self.newton_cut_steps += 1
            self.hold = HOLD_STEPS
        go = super().post_step(mbs, t)
        if t > 0.0 and self.hold > 0:
            self.hold -= 1
            self.next_step = min(self.next_step, h)
            self.it.currentStepSize = to_sample_grid(t, self.next_step, self.sample_period)
        self.planned = self.it.currentStepSize
        return go


def tree_jump(l_fg: float, l_ef: float):
    """``jump(a0, a1)`` of the journal centre from two joint-acceleration outputs [q0'', q1''] (module docstring).

    The sum of the two links' terms bounds the vector's length; the length itself (the angle between the
    links read from the state) changed the steps by 1 % on the loom (10 256 against 10 128 a revolution).
    """

    def jump(a0, a1) -> float:
        return l_fg * abs(a1[0] - a0[0]) + l_ef * abs(a1[0] + a1[1] - a0[0] - a0[1])

    return jump


class ImplicitTree:
    """Generalized-alpha with error control and friction segments on a built :class:`TreeModel`.

    ``install()`` before ``mbs.Assemble()``; :meth:`settings` for ``SolveSystem``.
    """

    def __init__(self, mbs: exu.MainSystem, solver: exu.MainSolverImplicitSecondOrder, model: TreeModel,
                 scene: Scene):
        # The explicit tree's largest step (a light impact must not begin and end inside one free-flight step;
        # gravity's fall through the clearance: selection.largest_step).
        s = scene.exudyn_solver
        self.mbs, self.solver, self.model, self.scene = mbs, solver, model, scene
        period = scene.output.sample_angle / scene.drive.speed
        self.max_step = largest_step(scene)
        g = scene.geometry
        stash = model.stash

        def gap(mbs_: exu.MainSystem) -> float:  # h_min = -delta of the callback's last state (post_newton: the trial)
            return -stash[1][callbacks.STASH_DELTA]

        self.control = TreeStepController(mbs, solver, model.node, 0.0, tree_local_error(scene),
                                          scene.limits.min_step, self.max_step, period, newmark_beta(SPECTRAL_RADIUS),
                                          jump=tree_jump(g.l_fg, g.l_ef), gap=gap,
                                          corners=film_corners(scene.joint))  # fmt: skip
        friction = scene.joint.friction_coefficient > 0.0
        self.segments = FrictionSegments(model.force) if friction else None

    def post_newton(self, mbs: exu.MainSystem, t: float) -> list[float]:
        """Friction piece first (Newton again on the right piece), then the step's error estimate."""
        model = self.model
        if model.stash[0] != t:  # Newton's last call, its convergence check, is at the converged state
            # (bit for bit, checked over 2 333 steps); a fresh evaluation only if that ever changes
            q = mbs.GetNodeOutput(model.node, OVT.Coordinates)
            q_t = mbs.GetNodeOutput(model.node, OVT.Coordinates_t)
            model.force(mbs, t, model.tree, q, q_t)
        if self.segments is not None and not self.segments.check(model.stash[1][callbacks.STASH_DELTA] > 0.0,
                                                                  model.stash[1][callbacks.STASH_SLIDING_SPEED]):
            return [_REPEAT, -1.0]
        return self.control.post_newton(mbs, t)

    def install(self) -> None:
        """Register the post-Newton function and the controller's post-step hook on the system."""
        self.mbs.SetPostNewtonUserFunction(self.post_newton)
        register_post_step(self.mbs, self.control.post_step)

    def settings(self, ss: exu.SimulationSettings) -> None:
        """Generalized-alpha on ``ss`` (end time, files and output set by the caller)."""
        scene = self.scene
        ti = ss.timeIntegration
        ti.solverType = exu.DynamicSolverType.GeneralizedAlpha
        ti.generalizedAlpha.spectralRadius = SPECTRAL_RADIUS
        ti.newton.useModifiedNewton = False
        # dry friction without a tape: the scenes of tree_solve.power_sums, where the looser tolerance was measured
        dry = scene.joint.friction_coefficient > 0.0 and not scene.joint.is_lubricated and scene.rapier_tape is None
        ti.newton.relativeTolerance = FRICTION_NEWTON_RELATIVE_TOLERANCE if dry else NEWTON_RELATIVE_TOLERANCE
        ti.newton.maxIterations = NEWTON_MAX_ITERATIONS
        ti.discontinuous.ignoreMaxIterations = False
        ti.discontinuous.maxIterations = MAX_SWITCHES
        # The controller sets every step from its post-step hook (the first at t = 0); Exudyn's own
        # lengthening after easy Newton steps is off; numberOfSteps sets its initial and largest step.
        ti.numberOfSteps = max(1, math.ceil(scene.drive.end_time / self.max_step * (1.0 - 1e-12)))
        ti.adaptiveStep = True
        ti.adaptiveStepRecoverySteps = 2**30
        ti.minimumStepSize = scene.limits.min_step

    def counters(self) -> dict:
        """Solver statistics of the run: the controller's, the steps cut after Newton failed (a step may have
        failed more than once before it was accepted), friction piece switches."""
        out = {**self.control.counters(), "newton_cut_steps": self.control.newton_cut_steps}
        if self.segments is not None:
            out["friction_switches"] = self.segments.switches
        return out
