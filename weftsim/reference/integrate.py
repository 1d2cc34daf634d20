"""Event-driven integration of the clearance-mode equations with scipy's one-step solvers.

The run is cut into segments at contact onset (delta crosses 0 upwards) and separation
(delta crosses 0 downwards).  Each segment is integrated by a fresh
:class:`scipy.integrate.OdeSolver` (method by name from :data:`METHODS`), stepped by hand
so that the loop sees every accepted step (recorded for peaks), evaluates the uniform
output grid through the step's dense output, detects the events and reports progress.

Events are located on the dense output of the step (:mod:`.events`: onset, separation and,
under the ``"max_approach"`` rule, the peak of the approach rate above the held impact
velocity), and the located state is taken from the side of the root that the new segment
needs: a contact segment starts with delta >= 0, a free one with delta <= 0.  A crossing counts
only where delta rises (onset) or falls (separation), and the first one inside the step is
taken, not only a change of sign between the step's ends.  At onset the penetration rate of
the located state is the held impact velocity delta_dot^-, floored at
``joint.min_impact_velocity``; under ``"max_approach"`` the contact force uses
max(held, delta_dot) (:func:`weftsim.joint.clearance.effective_impact_velocity`) and every maximum
of delta_dot above the held value ends the segment with that maximum as the new held value,
so delta_dot^- is exactly the largest approach rate since the onset.  Restarting the solver at
each event also keeps the method's order: the force law is only C^0 at delta = 0 and at
delta_dot = delta_dot^-.

The penetration guard looks at contact steps only: the end of a free-flight step that
crossed into the bearing is not a state of the model (no contact force acted on it); the
onset located inside the step is.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.checks.guards import Breach, RunGuard, failure_message, non_finite_breach
from weftsim.physics import chain as kernel_chain
from weftsim.physics.chain import rhs as chain_rhs
from weftsim.input.params import Scene
from weftsim.reference import events
from weftsim.model.dynamics import initial_state, pack_parameters

if TYPE_CHECKING:
    from collections.abc import Callable

# scipy.integrate's solvers by name (imported when a scipy method runs: not on the compiled path).
METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
# "auto": DOP853 is the fastest accurate method without friction (1 revolution of the reference
# scene: DOP853 0.7 s, LSODA 1.0 s, RK45 1.6 s, BDF 4.4 s, Radau 12 s); with friction the
# modified-Coulomb ramp (slope mu F_N / (v1 - v0) ~ 1e8 N s/m) makes sticking phases stiff and
# LSODA wins by ~30x (3.1 s against 88 s for DOP853).  See docs/reference-solver.md section 4.
AUTO = "auto"


def resolve_method(scene: Scene) -> str:
    """The scipy method name the scene's ``solver.reference.method`` stands for."""
    name = scene.reference_solver.method
    if name == AUTO:
        return "LSODA" if scene.joint.friction_coefficient > 0.0 else "DOP853"
    return name

# Right-hand-side evaluations per step attempt of the explicit Runge-Kutta methods
# (n_stages - 1 stages + f_new), per dense-output call (DOP853 adds 3 stages) and at
# the start of a segment (f0 and one trial in select_initial_step).
_RK_EVALS = {"DOP853": 12, "RK45": 6, "RK23": 3}
_DENSE_EVALS = {"DOP853": 3}
_START_EVALS = 2

_ROOT_XTOL = events.ROOT_XTOL
_PROGRESS_EVERY = 0.001  # report progress every 0.1 % of the run: the first line of a 1000-revolution run
# comes after one revolution, not ten, and the compiled loop (which pauses to report) sees a Ctrl-C within
# 0.1 % of the run (issue 16)
# Dense-output points recorded inside every step of a contact segment (besides the step ends):
# an impact pulse spans a few tens of steps, and its peak read at the step ends alone is low by
# up to ~1e-4 relative (DOP853, rtol 1e-9); 3 interior points cut that ~16-fold.
_CONTACT_SUBSTEPS = 3
_SUBSTEP_FRACTIONS = np.arange(1, _CONTACT_SUBSTEPS + 1) / (_CONTACT_SUBSTEPS + 1.0)
# The event search grid of a step: its ends and the contact substeps (events.SAMPLES intervals).
_GRID = np.linspace(0.0, 1.0, events.SAMPLES + 1)
assert events.SAMPLES == _CONTACT_SUBSTEPS + 1


@dataclass
class Trajectory:
    """Raw states of a clearance-mode run (filled by :func:`integrate`).

    ``step_*`` hold every accepted step, every located event and, in contact segments,
    ``_CONTACT_SUBSTEPS`` dense-output points inside each step; ``sample_*`` the
    uniform output grid.  ``*_contact`` is the segment's mode, ``*_impact`` the held,
    floored impact velocity of the segment (0 in free flight).
    """

    step_t: list = field(default_factory=list)
    step_y: list = field(default_factory=list)
    step_contact: list = field(default_factory=list)
    step_impact: list = field(default_factory=list)
    sample_t: list = field(default_factory=list)
    sample_y: list = field(default_factory=list)
    sample_contact: list = field(default_factory=list)
    sample_impact: list = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    events: dict = field(default_factory=dict)
    status: str = "success"
    message: str = ""

    def add_step(self, t: float, y: np.ndarray, contact: bool, impact: float) -> None:
        self.step_t.append(t)
        self.step_y.append(np.array(y[:6]))
        self.step_contact.append(contact)
        self.step_impact.append(impact)

    def add_samples(self, ts: np.ndarray, ys: np.ndarray, contact: bool, impact: float) -> None:
        for t, y in zip(ts, ys):
            self.sample_t.append(t)
            self.sample_y.append(np.array(y))
            self.sample_contact.append(contact)
            self.sample_impact.append(impact)


def _add_samples(traj: Trajectory, sample_times: np.ndarray, first: int, t_until: float, dense: Callable,
                 contact: bool, impact: float) -> int:
    """Record the output samples from index ``first`` up to ``t_until`` (inclusive) from the step's dense
    output; the index of the next sample."""
    stop = int(np.searchsorted(sample_times, t_until, side="right"))
    ts = sample_times[first:stop]
    traj.add_samples(ts, dense(ts).T, contact, impact)
    return stop


def penetration(prm: np.ndarray, t: float, y: np.ndarray) -> tuple[float, float]:
    """(delta, delta_dot) of a state y at time t: :func:`weftsim.physics.chain.penetration`."""
    return kernel_chain.penetration(prm, float(t), np.ascontiguousarray(y, dtype=float))


def make_rhs(prm: np.ndarray, counter: list) -> tuple[Callable, Callable]:
    """Right-hand sides y' = f(t, y) for free flight and for contact with held v_imp.

    The compiled right-hand side of :mod:`weftsim.physics.chain` (the one the compiled path
    integrates) on the scene's parameter array ``prm``; y = [a, psi, a', psi', W3, D] with
    W3' = -Q3 omega (contact power drawn through the rocker), D' = dissipated power.
    ``counter[0]`` counts the evaluations, ``counter[1]`` those that came out NaN or inf (scipy
    rejects such a step and shrinks it).
    """

    def evaluate(t, y, in_contact, impact_velocity):
        out = np.empty(6)
        chain_rhs(prm, float(t), y, in_contact, impact_velocity, out)
        counter[0] += 1
        if not math.isfinite(out[2] + out[3] + out[4] + out[5]):
            counter[1] += 1
        return out

    def free(t, y):
        return evaluate(t, y, False, 0.0)

    def contact_factory(impact_velocity):
        def contact(t, y):
            return evaluate(t, y, True, impact_velocity)

        return contact

    return free, contact_factory


def integrate(scene: Scene, progress: Callable[[float], None] | None = None) -> Trajectory:
    """Integrate the clearance-mode equations from t = 0 to the scene's end time.

    Never raises for a failing integration: the returned trajectory then has
    ``status = "failed"`` and a message naming time, crank angle and what to try.
    """
    with warnings.catch_warnings():
        # scipy's numerical Jacobian (Radau, BDF) overflows harmlessly in its step factor on
        # this stiff contact; real failures show as a failed step or a non-finite state.
        warnings.simplefilter("ignore", RuntimeWarning)
        return _integrate(scene, progress)


def _integrate(scene: Scene, progress) -> Trajectory:
    import scipy.integrate  # here, not at import: the compiled path never needs it (~0.5 s of a run)

    settings = scene.reference_solver
    name = resolve_method(scene)
    omega = scene.drive.speed
    t_end = scene.drive.end_time
    method = getattr(scipy.integrate, name)
    p = pack_parameters(scene)
    joint = scene.joint
    counter = [0, 0]
    free_rhs, contact_rhs = make_rhs(p, counter)
    max_step = settings.max_step / omega
    sample_dt = scene.output.sample_angle / omega
    n_samples = int(math.floor(t_end / sample_dt * (1.0 + 1e-12))) + 1
    sample_times = np.arange(n_samples) * sample_dt
    if t_end - sample_times[-1] > 1e-9 * sample_dt:
        sample_times = np.append(sample_times, t_end)

    traj = Trajectory()
    wall0 = _time.perf_counter()
    guard = RunGuard(scene)
    min_step = math.inf
    t, y = 0.0, initial_state(scene)
    contact, impact = False, 0.0
    next_sample = 0
    n_steps = n_segments = n_events = n_dense = n_impacts = n_peaks = n_nonpositive = 0
    track_max = joint.impact_velocity_rule == "max_approach"
    solver_evals = njev = nlu = 0
    first_contact = None
    max_penetration_rate = 0.0
    next_report = _PROGRESS_EVERY
    traj.add_step(t, y, contact, impact)
    if progress is not None:
        progress(0.0)

    def fail(text, hint=None, kind="solver"):
        traj.status = "failed"
        traj.stats["failure"] = kind
        traj.message = failure_message(
            f"reference solver ({name})", t, omega, text,
            hint or "try a smaller `solver.reference.max_step_deg`, a looser `solver.reference.rtol`/`atol`, or "
            "`solver.reference.method` = 'Radau' or 'LSODA'",
        )  # fmt: skip

    while t < t_end and traj.status == "success":
        fun = contact_rhs(impact) if contact else free_rhs
        try:
            solver = method(fun, t, y, t_end, rtol=settings.rtol, atol=settings.atol, max_step=max_step)
        except Exception as exc:  # noqa: BLE001 - reported as a failed run, never raised
            fail(f"cannot start a segment ({type(exc).__name__}: {exc})")
            break
        n_segments += 1
        breach: Breach | None
        event = None  # (kind, time, value): "onset" / "separation" (value: rate), "peak" (value: new held)
        g_old, r_old = penetration(p, t, y)
        sign = -1.0 if contact else 1.0  # the crossing looked for: delta falls (contact) / rises (free)
        while solver.status == "running":
            t_old = solver.t
            non_finite_before = counter[1]
            try:
                message = solver.step()
            except Exception as exc:  # noqa: BLE001
                fail(f"{type(exc).__name__}: {exc}")
                break
            if solver.status == "failed":
                # scipy gives up when the step it needs falls below the spacing of floats at t:
                # a collapse of the step size, often from a right-hand side that is NaN or inf.
                t = solver.t
                if counter[1] > non_finite_before:
                    breach = non_finite_breach(
                        "the right-hand side turned non-finite (NaN or inf) in the trials of the next step, "
                        f"which scipy shrank down to the float resolution of t ({message})"
                    )  # fmt: skip
                else:
                    collapsed = guard.check(step_size=10.0 * np.spacing(t), steps=0)
                    why = f"scipy: {message or 'step failed'}"
                    if name in ("Radau", "BDF"):
                        why += f"; {name} also halves the step when its Newton iterations do not converge"
                    if collapsed is None:  # limits.min_step_s below 10 floats of t (no criterion crossed)
                        collapsed = Breach("step_size", "the step size collapsed to the float resolution of t "
                                           f"(limits.min_step_s = {scene.limits.min_step:.3g} s is below it)", "")
                    breach = dataclasses.replace(collapsed, what=f"{collapsed.what}; {why}")
                fail(breach.what, breach.hint, breach.kind)
                break
            n_steps += 1
            t_new, y_new = solver.t, solver.y
            finite = bool(np.all(np.isfinite(y_new)))
            g_new, r_new = penetration(p, t_new, y_new) if finite else (math.nan, math.nan)
            # The step that lands on the end time is cut to fit and may be arbitrarily short.
            h = t_new - t_old if t_new < t_end else None
            if h is not None:
                min_step = min(min_step, h)
            # Only a contact step's end is a state of the model; a free step that ran into the
            # bearing is cut at the onset below.
            watched = None if (joint.is_ideal or not contact) else g_new
            breach = guard.check(penetration=watched, step_size=h, finite=finite)
            if breach is not None and breach.kind == "step_size" and counter[1] > non_finite_before:
                breach = non_finite_breach(
                    f"the right-hand side turned non-finite (NaN or inf) in the trials of this step, which "
                    f"shrank to {h:.3g} s (below limits.min_step_s = {scene.limits.min_step:.3g} s)"
                )  # fmt: skip
            possible = (sign * g_new > 0.0 or sign * r_old > 0.0 > sign * r_new) and not joint.is_ideal
            if breach is not None and breach.kind == "interrupted":
                # A stop asked for from outside: the accepted step is kept with its output samples, so that
                # the record ends within one sample of where the run says it stopped; a step in which a contact
                # event may lie is dropped instead (the run then ends where it began).
                if finite and not possible:
                    if next_sample < len(sample_times) and sample_times[next_sample] <= t_new:
                        next_sample = _add_samples(traj, sample_times, next_sample, t_new, solver.dense_output(),
                                                   contact, impact)  # fmt: skip
                    t = t_new
                    traj.add_step(t, y_new, contact, impact)
                fail(breach.what, breach.hint, breach.kind)
                break
            if breach is not None:
                t = t_new
                if finite:
                    traj.add_step(t, y_new, contact, impact)
                fail(breach.what, breach.hint, breach.kind)
                break
            t_stop = t_new
            # scipy's DenseOutput of the step (scipy is untyped: Any): made below whenever contact or an event
            # may lie in the step, so the contact substeps and an event's state read it, or for the samples
            dense: Any = None
            grid = None
            if contact or possible:
                dense = solver.dense_output()
                n_dense += 1
                grid = t_old + (t_new - t_old) * _GRID
                inner = [penetration(p, s, ys) for s, ys in zip(grid[1:-1], dense(grid[1:-1]).T)]
                deltas = [g_old] + [d for d, _ in inner] + [g_new]
                rates = [r_old] + [r for _, r in inner] + [r_new]

                def state(s, dense=dense):
                    return penetration(p, s, dense(s))

                found = events.first_crossing(state, grid, deltas, rates, sign) if possible else None
                if found is not None:
                    t_stop = found[0]
                    event = ("separation" if contact else "onset", t_stop, sign * found[1])
                if contact and track_max:
                    times, rs = list(grid), list(rates)
                    if event is not None:  # the approach rate counts up to the separation only
                        keep = [i for i, s in enumerate(times) if s < t_stop]
                        times = [times[i] for i in keep] + [t_stop]
                        rs = [rs[i] for i in keep] + [event[2]]
                    peak = events.rate_peak(lambda s: state(s)[1], times, rs, impact)
                    if peak is not None:
                        t_stop = peak[0]
                        event = ("peak", t_stop, peak[1])
            if next_sample < len(sample_times) and sample_times[next_sample] <= t_stop:
                if dense is None:
                    dense = solver.dense_output()
                    n_dense += 1
                next_sample = _add_samples(traj, sample_times, next_sample, t_stop, dense, contact, impact)
            if contact and _CONTACT_SUBSTEPS:
                # Impacts last tens of steps: read the pulse between steps too, for its peaks.
                ts = t_old + (t_stop - t_old) * _SUBSTEP_FRACTIONS
                for t_sub, y_sub in zip(ts, dense(ts).T):
                    traj.add_step(t_sub, y_sub, contact, impact)
            if event is not None:
                t, y = t_stop, dense(t_stop)
                break
            t, y = t_new, y_new
            g_old, r_old = g_new, r_new
            traj.add_step(t, y, contact, impact)
            if progress is not None and t >= next_report * t_end:
                progress(t / t_end)
                next_report = math.floor(t / t_end / _PROGRESS_EVERY + 1.0) * _PROGRESS_EVERY
        solver_evals += solver.nfev
        njev += getattr(solver, "njev", 0)
        nlu += getattr(solver, "nlu", 0)
        if event is None:
            continue
        n_events += 1
        kind, _, value = event
        if kind == "separation":
            contact, impact = False, 0.0
        elif kind == "peak":
            impact = value
            n_peaks += 1
        else:
            rate = value
            if not rate > 0.0:
                n_nonpositive += 1  # no rising root found: counted, and judged by weftsim.checks.guards
            max_penetration_rate = max(max_penetration_rate, rate)
            contact, impact = True, max(rate, joint.min_impact_velocity)
            n_impacts += 1
            if first_contact is None:
                first_contact = t
        traj.add_step(t, y, contact, impact)

    wall = _time.perf_counter() - wall0
    rejected = None
    if name in _RK_EVALS:
        attempts = (solver_evals - _START_EVALS * n_segments - _DENSE_EVALS.get(name, 0) * n_dense)
        rejected = max(int(round(attempts / _RK_EVALS[name])) - n_steps, 0)
    traj.stats = {
        "method": name,
        "rtol": settings.rtol,
        "atol": settings.atol,
        "max_step_rad": settings.max_step,
        "steps": n_steps,
        "rejected_steps": rejected,
        "function_evaluations": counter[0],
        "jacobian_evaluations": njev,
        "lu_decompositions": nlu,
        "dense_output_calls": n_dense,
        "segments": n_segments,
        "contact_events": n_events,
        "impacts": n_impacts,
        "rate_peaks": n_peaks,
        "nonpositive_onsets": n_nonpositive,
        "min_step_s": min_step if math.isfinite(min_step) else None,
        "wall_time_s": wall,
        **({"failure": traj.stats["failure"]} if "failure" in traj.stats else {}),
    }
    traj.events = {
        "first_contact_time_s": None if first_contact is None else float(first_contact),
        "max_impact_velocity_m_s": float(max_penetration_rate),
    }
    if progress is not None and traj.status == "success":
        progress(1.0)
    return traj
