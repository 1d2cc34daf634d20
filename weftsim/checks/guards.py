"""Run-time failure criteria shared by both engines (the scene's ``[limits]``).

A run must never end as a success after it went wrong.  Each engine makes one
:class:`RunGuard` per run and calls :meth:`RunGuard.check` after every accepted step
(or once per block of steps, with the block's extremes).  The first criterion crossed
comes back as a :class:`Breach`; the engine then stops, keeps what it computed and
returns ``status = "failed"`` with :func:`failure_message`: what failed, at which time
and crank angle, and what to try.  The criteria, in the order they are checked:

================  ==========================================  ==============================
kind              fails when                                  limit (scene ``[limits]``)
================  ==========================================  ==============================
``non_finite``    a state or channel is NaN or inf            always on
``penetration``   delta > max_penetration_ratio * R_j         ``max_penetration_ratio`` (0.1)
``step_size``     an accepted step h < min_step (or at it,    ``min_step_s`` (1e-12 s)
                  for a solver that goes on there unchecked)
``steps``         more than max_steps accepted steps          ``max_steps`` (0 = none)
``wall_time``     wall-clock time since the start > budget    ``max_wall_time_s`` (0 = none)
``energy``        W - dKE - dPE - E_contact - E_diss > limit  ``max_energy_error`` (0.01)
``plausibility``  a broken contact history (see below)        ``max_damping_ratio`` (1)
``interrupted``   the user stopped the run (Ctrl-C, SIGTERM)  :func:`request_stop`
================  ==========================================  ==============================

The last two need the whole run's channels: :func:`vet_result` checks them (and again the
first two) on every run an engine considers a success.  ``plausibility`` counts onsets with a
non-positive approach rate, steps whose damping force exceeds ``max_damping_ratio`` x xi x the
elastic force (under the ``max_approach`` rule, which bounds it), and contact steps with a negative
penetration (:mod:`weftsim.checks.plausibility`);
:func:`vet_result` also attaches those counts and the law-range warnings to every result.

Newton non-convergence is the engines' own (Exudyn's convergence flags; scipy's implicit
methods shrink the step until it collapses).  Why the defaults are what they are, and the
penetrations the hard cases reach, is in docs/hard-cases.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Callable, TYPE_CHECKING

import numpy as np

from weftsim.input.params import Limits, Scene

if TYPE_CHECKING:
    from weftsim.checks.plausibility import Plausibility
    from weftsim.post.results import RunResult

KINDS = ("non_finite", "penetration", "step_size", "steps", "wall_time", "energy", "plausibility", "interrupted")

# A stop asked for from outside the run (the command line's SIGINT handler): the signal is
# process-wide, so the request is too.  Every RunGuard sees it at its next check, and the engine
# ends the run as for any other breach, keeping what it computed.
_STOP_REQUEST: list[str] = []


def request_stop(reason: str) -> None:
    """Make every running :class:`RunGuard` report an ``interrupted`` breach at its next check."""
    _STOP_REQUEST[:] = [reason]


def stop_requested() -> str | None:
    """The reason given to :func:`request_stop` while a stop is asked for, else None."""
    return _STOP_REQUEST[0] if _STOP_REQUEST else None


def clear_stop() -> None:
    """Withdraw :func:`request_stop` (before the next run)."""
    _STOP_REQUEST.clear()


@dataclass(frozen=True)
class Breach:
    """A failure criterion that a run crossed.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    what : str
        What failed, with the value and the limit (naming its scene key).
    hint : str
        What to try.
    """

    kind: str
    what: str
    hint: str


def where(t: float, omega: float) -> str:
    """``"t = 0.0123 s, crank angle 29.520 deg"`` (with the revolution after the first one)."""
    deg = math.degrees(omega * t)
    text = f"t = {t:.6g} s, crank angle {deg:.3f} deg"
    if deg >= 360.0:
        revolution = int(deg // 360.0)
        text += f" (revolution {revolution + 1} at {deg - 360.0 * revolution:.3f} deg)"
    return text


def failure_message(engine: str, t: float, omega: float, what: str, hint: str) -> str:
    """One-line failure message: ``"<engine> failed at <where>: <what>; <hint>"``."""
    return f"{engine} failed at {where(t, omega)}: {what}; {hint}"


def non_finite_breach(what: str = "the state became non-finite (NaN or inf)") -> Breach:
    return Breach(
        "non_finite", what,
        "the forces or the state left the floating-point range: check the materials, clearance and law "
        "of [joint_e] (an absurd stiffness?) or try a smaller step / tighter tolerance",
    )  # fmt: skip


# What to try after a step collapse on the reference engine (the default of RunGuard's step_advice): the
# engines pass their own, naming their own solver keys.
REFERENCE_STEP_ADVICE = ("another method (solver.reference.method = 'Radau' or 'LSODA' for stiff contact) or a "
                         "looser solver.reference.rtol / atol")


def raised_min_step(scene: Scene) -> str:
    """``"a smaller limits.min_step_s (...), "`` when the scene raised it above its default, else ``""``: after a
    step collapse the floor, not the equations, may be what stopped the run."""
    default = Limits().min_step
    if scene.limits.min_step <= default:
        return ""
    return (f"a smaller limits.min_step_s (it is {scene.limits.min_step:.3g} s, raised from its default "
            f"{default:.3g} s: the impacts may need shorter steps), ")


def step_collapse_hint(scene: Scene, step_advice: str) -> str:
    """What to try after a step collapse: a raised ``limits.min_step_s`` first, then the engine's own
    ``step_advice``."""
    return (f"the equations became too stiff or discontinuous for the step control: try {raised_min_step(scene)}"
            f"{step_advice}, or check the joint's stiffness and the contact law")


# Bytes a recorded step row holds by the time a run's result is built: its time, state, contact mask and impact
# velocities (up to ~16 doubles) and some 25 response channels, times three for the working copies the channels
# are built through.  The loom with both pins worn records ~2.4 million rows a revolution (docs/wear.md
# section 10), ~2.3 GiB of channels for one 5-revolution wear update.
ROW_BYTES = 8 * 40 * 3


def memory_breach(rows: int, budget: float) -> Breach | None:
    """A breach when ``rows`` recorded steps would take more than ``budget`` bytes (at :data:`ROW_BYTES` each),
    else None: a run stopped here keeps its rows and says why, where it would end in a MemoryError or swap."""
    if rows * ROW_BYTES <= budget:
        return None
    return Breach(
        "memory",
        f"the run has recorded {rows:,} solver steps, about {rows * ROW_BYTES / 2**30:.2f} GiB with their "
        f"channels, more than half the memory that was free when it started ({budget / 2**30:.2f} GiB)",
        "simulate fewer revolutions (a wear prediction: a smaller wear.revolutions_per_update), a looser "
        "tolerance, or free memory",
    )


class RunGuard:
    """The ``[limits]`` of one run, checked step by step.

    Parameters
    ----------
    scene : Scene
        Its ``limits`` and journal radius set the bounds.
    clock : callable, optional
        Wall clock in seconds (tests pass a fake one); started here.
    step_advice : str
        What the engine that runs suggests after a step collapse, naming its solver keys
        (:data:`REFERENCE_STEP_ADVICE` for the reference engine).
    """

    def __init__(self, scene: Scene, clock: Callable[[], float] = time.perf_counter,
                 step_advice: str = REFERENCE_STEP_ADVICE):
        limits = scene.limits
        self.clock = clock
        self.start = clock()
        self.steps = 0
        self.max_wall_time = limits.max_wall_time if limits.max_wall_time > 0.0 else math.inf
        self.max_steps = limits.max_steps if limits.max_steps > 0 else None
        self.ratio = limits.max_penetration
        self.journal_radius = scene.joint.journal_radius
        self.max_penetration = limits.max_penetration * scene.joint.journal_radius
        # Joint F's bound, against its own journal radius (docs/clearance-f.md).
        self.max_penetration_f = limits.max_penetration * scene.joint_f.journal_radius
        self.min_step = limits.min_step
        self.step_hint = step_collapse_hint(scene, step_advice)

    @property
    def elapsed(self) -> float:
        """Wall-clock seconds since the guard was made."""
        return self.clock() - self.start

    def check(self, penetration: float | None = None, step_size: float | None = None, steps: int = 1,
              finite: bool = True, penetration_f: float | None = None, floor_fails: bool = False) -> Breach | None:
        """Count ``steps`` accepted steps and check every criterion.

        Parameters
        ----------
        penetration : float, optional
            Penetration delta = e - c of the joint after the step(s) (the largest one of a
            block), m; None for the ideal joint.
        step_size : float, optional
            Length of the accepted step (the shortest of a block), s; None for a fixed-step
            engine (its step floor is the solver's own setting).
        steps : int
            Accepted steps since the last call.
        finite : bool
            False if the engine found a NaN or inf in the state.
        penetration_f : float, optional
            The same at joint F; None while F is ideal.
        floor_fails : bool
            True for a solver that accepts a step at its floor without meeting its tolerance (Exudyn's
            explicit solvers print "reached minStepSize; integration continued" and go on at the floor,
            never below it): a step at limits.min_step_s is then a breach too.

        Returns
        -------
        Breach or None
        """
        self.steps += steps
        if _STOP_REQUEST:
            return Breach("interrupted", _STOP_REQUEST[0],
                          "what was computed up to here is kept; rerun to compute the whole run")
        # A step of the Exudyn tree calls this once (~1 us of the ~40 us a step): the common case, finite
        # penetrations within their bounds, is the two comparisons; anything else takes the checks in order.
        if not (finite and (penetration is None or -math.inf < penetration <= self.max_penetration)
                and (penetration_f is None or -math.inf < penetration_f <= self.max_penetration_f)):
            breach = self._state_breach(penetration, finite, penetration_f)
            if breach is not None:
                return breach
        if step_size is not None and step_size < self.min_step:
            return Breach(
                "step_size",
                f"the step size collapsed to {step_size:.3g} s (below limits.min_step_s = {self.min_step:.3g} s)",
                self.step_hint,
            )
        if floor_fails and step_size is not None and step_size <= self.min_step * (1.0 + 1e-9):
            return Breach(
                "step_size",
                f"the error tolerance cannot be met with steps of limits.min_step_s = {self.min_step:.3g} s "
                "(the solver reached its minimum step)",
                self.step_hint,
            )
        if self.max_steps is not None and self.steps > self.max_steps:
            return Breach(
                "steps",
                f"the run needs more than limits.max_steps = {self.max_steps} accepted steps",
                "raise limits.max_steps, simulate fewer revolutions, or use a larger step or looser tolerance",
            )
        elapsed = self.elapsed
        if elapsed > self.max_wall_time:
            return Breach(
                "wall_time",
                f"the wall-time budget limits.max_wall_time_s = {self.max_wall_time:g} s is spent "
                f"({elapsed:.3g} s, {self.steps} steps)",
                "raise limits.max_wall_time_s or simulate fewer revolutions",
            )
        return None

    def _state_breach(self, penetration: float | None, finite: bool, penetration_f: float | None) -> Breach | None:
        """The state's checks of :meth:`check`: a NaN or inf first, then each joint's penetration bound."""
        if not finite or any(p is not None and not math.isfinite(p) for p in (penetration, penetration_f)):
            return non_finite_breach()
        for table, value, bound in (("joint_e", penetration, self.max_penetration),
                                    ("joint_f", penetration_f, self.max_penetration_f)):
            if value is not None and value > bound:
                return Breach(
                    "penetration",
                    f"the penetration {value * 1e3:.4f} mm exceeds {self.ratio:g} of the journal radius "
                    f"({bound * 1e3:.4f} mm, limits.max_penetration_ratio)",
                    "the joint is too soft for its load or the contact law is used far outside its range: check "
                    f"the materials, clearance and law of [{table}]; raise limits.max_penetration_ratio only if "
                    "such a deformation is meant",
                )  # fmt: skip
        return None


_ENGINE_LABELS = {"reference": "reference solver", "exudyn": "Exudyn engine"}


def _first(mask) -> int | None:
    idx = np.flatnonzero(mask)
    return int(idx[0]) if idx.size else None


def energy_residual(steps: dict) -> np.ndarray:
    """W - dKE - dPE - dE_contact - dE_dissipated at every step, J (zero for exact conservation)."""
    return (
        steps["driving_work_J"] - steps["driving_work_J"][0]
        - (steps["kinetic_energy_J"] - steps["kinetic_energy_J"][0])
        - (steps["potential_energy_J"] - steps["potential_energy_J"][0])
        - (steps["contact_energy_J"] - steps["contact_energy_J"][0])
        - (steps["dissipated_energy_J"] - steps["dissipated_energy_J"][0])
    )  # fmt: skip


def result_breach(result: RunResult) -> tuple[int, Breach] | None:
    """The first step of a finished run's channels that crosses a criterion, and the breach.

    Checked on the per-step channels, in this order: non-finite values, the penetration
    bound, the energy balance (``limits.max_energy_error`` of the largest kinetic energy).
    The last one catches what no step-by-step check sees: a step too long for the impacts
    (e.g. a joint 5e8 times stiffer than steel at Exudyn's 2e-6 s step made 1.5e11 N and
    created 3 times the kinetic energy, with Newton converging at every step).
    """
    st = result.steps
    if st["time_s"].size == 0:
        return None
    finite = np.ones(st["time_s"].size, dtype=bool)
    for values in st.values():
        finite &= np.isfinite(values)
    i = _first(~finite)
    if i is not None:
        return i, non_finite_breach("non-finite values (NaN or inf) in the results")
    from weftsim.checks.plausibility import joint_view

    scene = result.scene
    for joint in scene.loose_joints:  # each joint against its own journal radius
        joint_scene, joint_steps = joint_view(result, joint)
        guard = RunGuard(joint_scene)
        i = _first(joint_steps["penetration_m"] > guard.max_penetration)
        if i is not None:
            breach = guard.check(penetration=float(joint_steps["penetration_m"][i]), steps=0)
            if breach is not None:
                return i, breach
    residual = energy_residual(st)
    scale = float(np.max(np.abs(st["kinetic_energy_J"]))) or 1.0
    limit = scene.limits.max_energy_error
    i = _first(np.abs(residual) > limit * scale)
    if i is not None:
        return i, Breach(
            "energy",
            f"the energy balance misses by {residual[i]:.4g} J, {abs(residual[i]) / scale:.3g} of the largest kinetic "
            f"energy {scale:.4g} J (limits.max_energy_error = {limit:g})",
            "the steps do not resolve the contact (too long a step for this stiffness): try a smaller step or "
            "tighter tolerance, or check the materials of [joint_e]",
        )  # fmt: skip
    return None


def plausibility_breach(result: RunResult, report: Plausibility) -> tuple[int, Breach] | None:
    """The first step showing a defect of :func:`weftsim.checks.plausibility.assess`'s report, and the breach."""
    from weftsim.checks.plausibility import HINT, first_defect_row

    defects = report.defects()
    if not defects:
        return None
    return first_defect_row(result, report), Breach("plausibility", "; ".join(defects), HINT)


def vet_result(result: RunResult) -> RunResult:
    """``result`` with its plausibility report and design checks attached (:func:`weftsim.checks.design_checks.block`),
    failed if a criterion is crossed.

    Applied by both engines to every run, so a criterion crossed without the step-by-step
    checks seeing it still fails the run: :func:`result_breach`, then the defects of
    :func:`weftsim.checks.plausibility.assess`.  Runs that already failed keep their message and
    get the report only.  The channels are kept whole (the run did finish); the message
    names the first step concerned.
    """
    from weftsim.checks.design_checks import block
    from weftsim.checks.plausibility import assess

    report = assess(result)
    result = replace(result, plausibility=block(result, {} if report is None else report.as_dict()))
    if not result.ok:
        return result
    found = result_breach(result)
    if found is None and report is not None:
        found = plausibility_breach(result, report)
    if found is None:
        return result
    i, breach = found
    t = float(result.steps["time_s"][i])
    message = failure_message(_ENGINE_LABELS.get(result.engine, result.engine), t, result.scene.drive.speed,
                              breach.what, breach.hint)  # fmt: skip
    stats = {**result.solver_stats, "failure": breach.kind}
    return replace(result, status="failed", message=message, solver_stats=stats)
