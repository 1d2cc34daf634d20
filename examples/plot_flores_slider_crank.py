"""
Flores slider-crank: a revolute clearance joint between rod and slider
======================================================================

The classic benchmark of the clearance-joint literature (Flores and Ambrosio, Comput. Struct. 82,
2004): a slider-crank whose piston pin B, between the connecting rod and the slider, has a radial
clearance of 0.5 mm, the crank driven at 5000 rpm.  The pin is modelled with weftsim's reusable
Exudyn joint, :func:`weftsim.exudyn_engine.add_clearance_joint`, and the Lankarani-Nikravesh law.

The example

- builds the mechanism in an Exudyn system (crank and rod rigid bodies, slider a mass point),
- runs its own step-size study of the peak contact force and of the slider acceleration over the
  steady crank revolutions, with the energy balance (the ideal joint is checked against the
  slider-crank's closed form, the start-up impact against a one-degree-of-freedom model),
- draws the journal centre's orbit inside the clearance circle, impacts marked.

Run it as a script: ``python examples/plot_flores_slider_crank.py`` (coarse steps, seconds) or
``python examples/plot_flores_slider_crank.py --fine`` (the full study, minutes).  docs/clearance-joint.md
discusses the results against the paper.
"""

# %%
# The mechanism
# -------------
# (Built in examples/flores_mechanism.py, shared with the lubricated slider-crank.)
# Crank OA (length r, turning about O at constant speed omega) - rod AB (length l) - slider B on
# the X axis, all in Exudyn's XY plane, gravity along -Y.  At B the slider carries the bearing
# (radius R_b = R_j + c) and the rod the journal (radius R_j); the
# :class:`~weftsim.input.params.ClearanceJoint` is given every value explicitly.  Parameters of Flores
# and Ambrosio (2004); assumed here: the crank and rod centres of mass at their midpoints.  The
# crank angle theta starts at 0 (B at its outer dead centre), the journal centred,
# every velocity that of the ideal mechanism.

from __future__ import annotations

import argparse
import math
import sys

import matplotlib.pyplot as plt
import numpy as np

# The mechanism, its joint, the solver settings and the closed form of the ideal joint are shared with
# the lubricated slider-crank (plot_lubricated_slider_crank.py): examples/flores_mechanism.py.
from flores_mechanism import (  # noqa: F401  (re-exported: the tests read them from this example)
    CRANK_INERTIA,
    CRANK_LENGTH,
    CRANK_MASS,
    CRANK_SPEED,
    FLORES_FRICTION,
    GRAVITY,
    REVOLUTION,
    ROD_INERTIA,
    ROD_LENGTH,
    ROD_MASS,
    SLIDER_MASS,
    STEEL,
    SliderCrank,
    build,
    flores_joint,
    ideal_slider_acceleration,
    settings,
    simulate,
)
from weftsim.input.params import ClearanceJoint

def _cumulative(rate, time):
    """Trapezoid integral of ``rate`` over ``time`` from the first sample."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(time))])


def energy_balance(run: dict) -> dict:
    """Energy terms since t = 0, J: driving work = kinetic + potential + contact + dissipated + rest.

    The drive's work is the trapezoid sum of T omega (T the velocity constraint's force on the crank
    coordinate); kinetic and potential energy of the three bodies; the contact's elastic energy
    ``law.elastic_energy(delta)`` and the work of its damping term, the trapezoid sum of
    (F_N - F_el(delta)) delta_dot.  ``residual`` = work - the others: the integrator's own
    dissipation (generalized-alpha, spectral radius 0.8) and the quadrature error of the sums;
    with friction it also holds the friction work, which this balance does not separate.
    """
    t, theta = run["time"], run["theta"]
    r, omega = CRANK_LENGTH, CRANK_SPEED
    crank_inertia = CRANK_INERTIA + CRANK_MASS * (r / 2.0) ** 2  # about O
    rod = 0.5 * ROD_MASS * np.sum(run["rod_velocity"] ** 2, axis=1) + 0.5 * ROD_INERTIA * run["rod_rate"] ** 2
    kinetic = 0.5 * crank_inertia * omega**2 + rod + 0.5 * SLIDER_MASS * run["slider_velocity"] ** 2
    potential = GRAVITY * (CRANK_MASS * 0.5 * r * np.sin(theta) + ROD_MASS * run["rod_height"])
    terms = {"work": _cumulative(-run["drive_force"] * omega, t), "kinetic": kinetic - kinetic[0],
             "potential": potential - potential[0]}  # fmt: skip
    if "model" in run:
        law = run["model"].law
        delta = np.linalg.norm(run["eccentricity"], axis=1) - run["model"].joint.clearance
        elastic = law.elastic_force(delta)
        terms["contact"] = law.elastic_energy(delta)
        terms["dissipated"] = _cumulative((run["normal_force"] - elastic) * run["penetration_rate"], t)
    terms["residual"] = terms["work"] - sum(v for k, v in terms.items() if k != "work")
    return terms


def start_up_impact(joint: ClearanceJoint) -> dict:
    """The first impact from a one-degree-of-freedom model, integrated with scipy (rtol 1e-11).

    The journal starts centred and the slider at rest at the dead centre, so the slider does not
    move until the journal, pulled inwards by the rod at r omega^2 (1 + r / l), has crossed the
    clearance: it hits the slider almost along the rod (theta ~ 7 deg).  Along the rod the journal
    is driven by the crank (prescribed speed), so this impact is, to first order, the slider mass
    m_s hitting a wall that moves as the ideal pin B, x_B(t) (:func:`ideal_slider_acceleration`):

        delta = x_s - x_B(t) - c,   m_s x_s'' = -F_N(delta, delta_dot, v_imp),   delta_dot = x_s' - x_B'

    What it leaves out: the rod's angle (cos 7 deg = 0.993 of the push along X) and its rotation.

    Returns
    -------
    dict
        ``onset_time`` (s), ``impact_velocity`` (m/s), ``peak_force`` (N), ``max_penetration`` (m),
        ``duration`` (s, onset to separation).
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    from weftsim.joint.contact import make_law

    r, l, omega, c = CRANK_LENGTH, ROD_LENGTH, CRANK_SPEED, joint.clearance
    force = make_law(joint).scalar()

    def pin(t):
        s, co = math.sin(omega * t), math.cos(omega * t)
        big_s = math.sqrt(l * l - (r * s) ** 2)
        return r * co + big_s, -omega * (r * s + r * r * s * co / big_s)

    x0 = r + l
    onset = brentq(lambda t: x0 - pin(t)[0] - c, 0.0, 0.25 * REVOLUTION, xtol=1e-16, rtol=1e-15)
    v_imp = -pin(onset)[1]

    def rhs(t, y):
        x_b, v_b = pin(t)
        return [y[1], -force(y[0] - x_b - c, y[1] - v_b, v_imp) / SLIDER_MASS]

    def separated(t, y):
        return y[0] - pin(t)[0] - c

    separated.terminal, separated.direction = True, -1.0
    sol = solve_ivp(rhs, (onset, onset + 0.05 * REVOLUTION), [x0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-15, events=separated, dense_output=True, first_step=1e-9)  # fmt: skip
    t = np.linspace(sol.t[0], sol.t[-1], 20001)
    x_b, v_b = np.array([pin(ti) for ti in t]).T
    y = sol.sol(t)
    f = np.array([force(d, v, v_imp) for d, v in zip(y[0] - x_b - c, y[1] - v_b)])
    return {"onset_time": onset, "impact_velocity": v_imp, "peak_force": float(f.max()),
            "max_penetration": float((y[0] - x_b - c).max()), "duration": float(sol.t[-1] - onset)}  # fmt: skip


def first_contact(run: dict) -> slice:
    """Indices of the first contact (start-up impact): from its onset to the first separation."""
    inside = run["in_contact"] > 0.0
    start = int(np.argmax(inside))
    stop = start + int(np.argmax(~inside[start:]))
    return slice(start, stop)


def revolution_statistics(run: dict, skip: int = 1) -> dict:
    """Per crank revolution after the first ``skip``: peak F_N, peak |a_slider| and RMS a_slider."""
    n = int(round(run["time"][-1] / REVOLUTION))
    peaks, acc_peaks, acc_rms = [], [], []
    for k in range(skip, n):
        sel = (run["time"] >= k * REVOLUTION) & (run["time"] < (k + 1) * REVOLUTION)
        a = run["slider_acceleration"][sel]
        peaks.append(run["normal_force"][sel].max())
        acc_peaks.append(np.abs(a).max())
        acc_rms.append(math.sqrt(np.mean(a * a)))
    return {"peak_force": np.array(peaks), "peak_acceleration": np.array(acc_peaks),
            "rms_acceleration": np.array(acc_rms)}  # fmt: skip


STUDY_COLUMNS = {  # label: (row key, unit scale, format)
    "start-up F_N (kN)": ("startup_peak", 1e-3, "{:.4f}"),
    "steady peak F_N (kN)": ("peak_force", 1e-3, "{:.2f}"),
    "steady peak |a| (km/s2)": ("peak_acceleration", 1e-3, "{:.1f}"),
    "steady RMS a (km/s2)": ("rms_acceleration", 1e-3, "{:.2f}"),
}


def convergence_study(steps, revolutions: int, friction_coefficient: float = 0.0) -> list[dict]:
    """Run the clearance model at every step; one row per step (steady values: mean over revolutions 2..).

    The peak of the start-up impact is a converged quantity (an isolated impact from a defined
    state); the steady values are means over revolutions of a motion whose impact sequence is
    sensitive to any perturbation, so each carries its standard error (``*_sem``) and the
    change on halving is only meaningful against it.  If the installed weftsim refuses friction,
    the study returns one row with the ``error`` it raised.
    """
    rows = []
    for step in steps:
        try:
            run = simulate(step, revolutions, flores_joint(friction_coefficient))
        except NotImplementedError as err:
            return [{"step": step, "error": str(err)}]
        stats = revolution_statistics(run)
        energy = energy_balance(run)
        row = {"step": step, "startup_peak": float(run["normal_force"][first_contact(run)].max()),
               "contacts_per_revolution": run["model"].tracker.contact_events / revolutions,
               "dissipated": float(energy["dissipated"][-1]),
               "energy_residual": float(np.abs(energy["residual"]).max()),
               "run": run}  # fmt: skip
        for key, values in stats.items():
            row[key + "_range"] = (float(values.min()), float(values.max()))
            row[key] = float(values.mean())
            row[key + "_sem"] = float(values.std(ddof=1) / math.sqrt(len(values))) if len(values) > 1 else math.nan
        rows.append(row)
    return rows


def format_study(rows: list[dict]) -> str:
    """Markdown table: step, the values of :data:`STUDY_COLUMNS` and their relative change on halving."""
    if "error" in rows[0]:
        return f"not run: {rows[0]['error']}"
    head = ["step (s)"] + [f"{label} (change)" for label in STUDY_COLUMNS]
    head += ["contacts/rev", "dissipated (J)", "max energy residual (J)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for i, row in enumerate(rows):
        cells = [f"{row['step']:.3g}"]
        for key, scale, fmt in STUDY_COLUMNS.values():
            value = fmt.format(row[key] * scale)
            if key + "_sem" in row:
                value += " +- " + fmt.format(row[key + "_sem"] * scale)
            change = f" ({row[key] / rows[i - 1][key] - 1.0:+.1e})" if i else ""
            cells.append(value + change)
        cells += [f"{row['contacts_per_revolution']:.1f}", f"{row['dissipated']:.3f}", f"{row['energy_residual']:.1e}"]
        lines.append("| " + " | ".join(cells) + " |")
    spans = []
    for label, (key, scale, _) in list(STUDY_COLUMNS.items())[1:]:
        low = min(row[key + "_range"][0] for row in rows) * scale
        high = max(row[key + "_range"][1] for row in rows) * scale
        spans.append(f"{label.replace('steady ', '')} {low:.3g} .. {high:.3g}")
    lines.append("\nsingle steady revolutions, all steps: " + "; ".join(spans))
    return "\n".join(lines)


def impacts(run: dict) -> np.ndarray:
    """Indices of the first accepted state of every contact (onsets)."""
    inside = run["in_contact"] > 0.0
    return np.flatnonzero(inside[1:] & ~inside[:-1]) + 1


def plot_orbit(run: dict, revolution: int = 1, ax=None):
    """Journal centre relative to the bearing centre (mm) over one crank revolution, impacts marked."""
    if ax is None:
        ax = plt.figure(figsize=(5.2, 5.6)).add_subplot()
    c = run["model"].joint.clearance * 1e3
    keep = (run["time"] >= revolution * REVOLUTION) & (run["time"] <= (revolution + 1) * REVOLUTION)
    e = run["eccentricity"] * 1e3
    hits = impacts(run)
    hits = hits[keep[hits]]
    angle = np.linspace(0.0, 2.0 * math.pi, 361)
    ax.plot(c * np.cos(angle), c * np.sin(angle), "k--", lw=0.8, label=f"clearance circle, c = {c:g} mm")
    ax.plot(e[keep, 0], e[keep, 1], lw=0.8, label="journal centre")
    ax.plot(e[hits, 0], e[hits, 1], "rx", ms=6, label=f"impacts ({len(hits)})")
    ax.set(xlabel="e_x (mm), along the slider's rail", ylabel="e_y (mm)", aspect="equal",
           xlim=(-1.2 * c, 1.2 * c), ylim=(-1.2 * c, 1.2 * c),
           title=f"Journal orbit, revolution {revolution + 1}")  # fmt: skip
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=7)
    return ax.figure


def plot_acceleration(run: dict, ideal: dict, revolution: int = 1, ax=None):
    """Slider acceleration over one crank revolution against the ideal joint's closed form."""
    if ax is None:
        ax = plt.figure(figsize=(7.0, 3.6)).add_subplot()
    sel = (run["time"] >= revolution * REVOLUTION) & (run["time"] < (revolution + 1) * REVOLUTION)
    deg = np.degrees(run["theta"][sel]) - 360.0 * revolution
    ax.plot(deg, run["slider_acceleration"][sel] * 1e-3, lw=0.6, label="clearance c = 0.5 mm")
    ax.plot(deg, ideal_slider_acceleration(run["theta"][sel]) * 1e-3, "k", lw=1.2, label="ideal joint (closed form)")
    ax.set(xlabel="crank angle (deg)", ylabel="slider acceleration (km/s$^2$)", xlim=(0, 360),
           title=f"Slider acceleration, revolution {revolution + 1}")  # fmt: skip
    ax.legend(fontsize=7)
    return ax.figure


def options() -> argparse.Namespace:
    """Command-line options; sphinx-gallery (and an import) get the defaults: the coarse study."""
    parser = argparse.ArgumentParser(description="Flores slider-crank with a clearance joint")
    parser.add_argument("--fine", action="store_true", help="full step-size study (minutes)")
    parser.add_argument("--save", metavar="DIR", help="write the figures as DIR/flores_*.png")
    return parser.parse_known_args(sys.argv[1:] if __name__ == "__main__" else [])[0]


# %%
# Ideal joint against the closed form
# -----------------------------------
# With an ideal revolute joint at B the slider's acceleration is that of the slider-crank at
# constant crank speed, peak r omega^2 (1 + r / l) = 19.42 km/s^2 at theta = 0.

OPTIONS = options()
FINE = OPTIONS.fine
COARSE_STEPS, FINE_STEPS = (2e-6, 1e-6, 5e-7), (2e-6, 1e-6, 5e-7, 2.5e-7, 1.25e-7)
STEPS = FINE_STEPS if FINE else COARSE_STEPS
REVOLUTIONS = 21 if FINE else 3  # the first revolution holds the start-up impacts

ideal = simulate(STEPS[-1], 1.0)
ideal_error = np.abs(ideal["slider_acceleration"] - ideal_slider_acceleration(ideal["theta"])).max()
ideal_rms = math.sqrt(np.mean(ideal["slider_acceleration"] ** 2))
print(f"ideal joint, h = {STEPS[-1]:.3g} s: peak |a| {np.abs(ideal['slider_acceleration']).max():.1f} m/s^2, "
      f"RMS {ideal_rms:.1f} m/s^2, largest deviation from the closed form {ideal_error:.2e} m/s^2")  # fmt: skip

# %%
# The start-up impact
# -------------------
# Started centred, the journal crosses the clearance in 0.23 ms and hits the resting slider at
# about 4.4 m/s: the hardest impact of the run.  A one-degree-of-freedom model of it
# (:func:`start_up_impact`) gives its peak force and penetration independently of Exudyn.

impact = start_up_impact(flores_joint())
print(f"1-DOF start-up impact: onset {impact['onset_time'] * 1e3:.5f} ms, v_imp {impact['impact_velocity']:.4f} m/s, "
      f"peak F_N {impact['peak_force']:.1f} N, max penetration {impact['max_penetration'] * 1e6:.3f} um, "
      f"duration {impact['duration'] * 1e6:.1f} us")  # fmt: skip

# %%
# Step-size study, without friction
# ---------------------------------
# Peak contact force of the start-up impact and, over the steady revolutions (2 onwards), the mean
# per revolution of the peak contact force, of the peak slider acceleration and of its RMS value,
# each +- its standard error over the revolutions; in brackets the relative change on halving
# the step.

study = convergence_study(STEPS, REVOLUTIONS)
print(format_study(study))

# %%
# Step-size study, with friction
# ------------------------------
# The same with the modified Coulomb friction of the joint, mu = FLORES_FRICTION.  A weftsim whose
# Exudyn joint does not carry friction yet says so here instead of running.  The energy residual
# then includes the friction work.

# Friction makes every step several times dearer (full Newton, loads Jacobian): the coarse run
# keeps two steps and two revolutions.
friction_study = convergence_study(STEPS if FINE else STEPS[:2], REVOLUTIONS if FINE else 2, FLORES_FRICTION)
print(f"mu = {FLORES_FRICTION}:")
print(format_study(friction_study))

# %%
# Orbit of the journal centre
# ---------------------------
# Finest step, the second crank revolution: the journal runs along the bearing wall (continuous
# contact, with small rebounds) over much of the revolution and crosses the clearance (free
# flight, then an impact) where the load on the pin reverses.

orbit = plot_orbit(study[-1]["run"])

# %%
# Slider acceleration
# -------------------

acceleration = plot_acceleration(study[-1]["run"], ideal)

if OPTIONS.save:
    orbit.savefig(f"{OPTIONS.save}/flores_orbit.png", dpi=120, bbox_inches="tight")
    acceleration.savefig(f"{OPTIONS.save}/flores_acceleration.png", dpi=120, bbox_inches="tight")
if __name__ == "__main__" and not OPTIONS.save:
    plt.show()
