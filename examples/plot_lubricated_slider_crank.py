"""
Lubricated slider-crank: an oil film in the piston pin
======================================================

The slider-crank of the dry example (:doc:`plot_flores_slider_crank`) with oil in its piston pin B,
as Flores, Ambrosio, Claro and Lankarani (Mech. Mach. Theory 41, 2006) and Flores et al. ("Kinematics
and Dynamics of Multibody Systems with Imperfect Joints", Springer 2008) study it: crank 0.05 m, rod
0.12 m, crank at 5000 rpm, journal and bearing radii 9.5 and 10 mm (radial clearance 0.5 mm), bearing
40 mm long, oil of 400 cP (0.4 Pa s).  The pin is weftsim's reusable Exudyn joint with a
:class:`~weftsim.input.params.Lubrication`: the film force of :mod:`weftsim.physics.film` acts at every
eccentricity, the dry contact law only beyond the clearance.

Two film models: ``"short_half"``, the short bearing as the paper writes it, and ``"finite"``,
weftsim's finite-length film (the pin has B/D = 2.1, where the short bearing overestimates the load).
Against the dry pin of the same size, the figures show what the paper shows: the lubricated journal
orbits inside the clearance circle, the dry one flies across it and hits the wall; the slider's
acceleration with the film is smooth and close to the ideal joint's, the dry pin's has the impacts'
spikes.

Run it as a script: ``python examples/plot_lubricated_slider_crank.py`` (about 20 s).
"""

# %%
# The runs
# --------
# Two crank revolutions from the centred journal, generalized-alpha at a fixed step of 2e-6 s (the dry
# example's coarsest step; the film's torques are loads read from the state, so the solver runs full
# Newton with their Jacobian, as with friction).  The mechanism is that of the dry example
# (examples/flores_mechanism.py); the ideal joint is the slider-crank's closed form.
# Halving the step (measured, 1e-6 s) changes the oiled runs' largest eccentricity ratio e/c by 1.5e-6
# (short_half) and 1e-6 (finite) and their RMS deviation from the ideal acceleration by 6e-5 and 8e-5
# (relative).

from __future__ import annotations

import math
import sys
import time

import matplotlib.pyplot as plt
import numpy as np
from flores_mechanism import REVOLUTION, ideal_slider_acceleration, lubricated_joint, simulate

STEP = 2e-6  # s
REVOLUTIONS = 2.0
MODELS = {"dry": None, "short_half": "short_half", "finite": "finite"}  # label: film model


def eccentricity_ratio(run: dict) -> np.ndarray:
    """|e| / c at every accepted step."""
    return np.linalg.norm(run["eccentricity"], axis=1) / run["model"].joint.clearance


def film_history(run: dict) -> dict:
    """The lubricated joint's record at every accepted state: time, dissipated power D' (W), film force
    |f_film| (N), asperity load F_a (N) (``model.friction.lubrication_history``)."""
    rows = np.array(run["model"].friction.lubrication_history).reshape(-1, 6)  # t, D', U_a, |f_film|, F_a, T_j
    return {"time": rows[:, 0], "dissipated_power": rows[:, 1], "film_force": rows[:, 3], "asperity_load": rows[:, 4]}


def acceleration_deviation(run: dict, revolution: int | None = 1) -> float:
    """RMS of the slider acceleration minus the ideal joint's over one crank revolution (None: the whole
    run), m/s^2."""
    sel = np.ones_like(run["time"], dtype=bool)
    if revolution is not None:
        sel = (run["time"] >= revolution * REVOLUTION) & (run["time"] < (revolution + 1) * REVOLUTION)
    deviation = run["slider_acceleration"][sel] - ideal_slider_acceleration(run["theta"][sel])
    return math.sqrt(np.mean(deviation**2))


runs, seconds = {}, {}
for label, model in MODELS.items():
    start = time.perf_counter()
    runs[label] = simulate(STEP, REVOLUTIONS, lubricated_joint(model))
    seconds[label] = time.perf_counter() - start

print(" pin         | max |e|/c | contacts | RMS(a - a_ideal), rev. 2 | run time")
for label, run in runs.items():
    print(f" {label:11s} | {eccentricity_ratio(run).max():9.3f} | {run['model'].tracker.contact_events:8d} | "
          f"{acceleration_deviation(run) / 1e3:17.3f} km/s^2 | {seconds[label]:5.1f} s")

# %%
# The film carries the pin
# ------------------------
# With oil the journal never reaches the wall: the film's pressure alone carries the load (no
# asperity load, no dry contact), and the film dissipates energy at every state (D' >= 0; the
# wedge and squeeze films only take work from the mechanism).

for label in ("short_half", "finite"):
    film = film_history(runs[label])
    dissipated = np.sum(0.5 * (film["dissipated_power"][1:] + film["dissipated_power"][:-1]) * np.diff(film["time"]))
    print(f"{label}: peak film force {film['film_force'].max():.0f} N, peak asperity load "
          f"{film['asperity_load'].max():.0f} N, smallest D' {film['dissipated_power'].min():.2f} W, "
          f"film dissipation over the run {dissipated:.2f} J")  # fmt: skip

# %%
# The journal's orbit
# -------------------
# The eccentricity vector over the second revolution, over the clearance c: the unit circle is the
# bearing wall.


def plot_orbits(runs: dict, revolution: int = 1):
    """Eccentricity-ratio loci of every run over one crank revolution."""
    fig, ax = plt.subplots(figsize=(5.6, 5.8))
    angle = np.linspace(0.0, 2.0 * math.pi, 361)
    ax.plot(np.cos(angle), np.sin(angle), "k--", lw=0.8, label="bearing wall, |e| = c")
    styles = {"dry": dict(color="tab:red", lw=0.6), "short_half": dict(color="tab:blue", lw=1.2),
              "finite": dict(color="tab:green", lw=1.2)}  # fmt: skip
    for label, run in runs.items():
        keep = (run["time"] >= revolution * REVOLUTION) & (run["time"] <= (revolution + 1) * REVOLUTION)
        eps = run["eccentricity"][keep] / run["model"].joint.clearance
        ax.plot(eps[:, 0], eps[:, 1], label="dry" if label == "dry" else f"oil, {label}", **styles[label])
    ax.set(xlabel="e_x / c (along the slider's rail)", ylabel="e_y / c", aspect="equal", xlim=(-1.25, 1.25),
           ylim=(-1.25, 1.25), title=f"Journal orbit in the clearance, revolution {revolution + 1}")  # fmt: skip
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=7)
    return fig


orbits = plot_orbits(runs)

# %%
# Slider acceleration
# -------------------


def plot_accelerations(runs: dict, revolution: int = 1):
    """Slider acceleration over one crank revolution against the ideal joint: the dry pin (top) and the
    lubricated ones (bottom, at the ideal's scale)."""
    fig, axes = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    theta = np.linspace(0.0, 2.0 * math.pi, 721)
    panels = ((axes[0], (("dry", "tab:red", 0.5),)),
              (axes[1], (("short_half", "tab:blue", 1.0), ("finite", "tab:green", 1.0))))  # fmt: skip
    for ax, lines in panels:
        for label, color, lw in lines:
            run = runs[label]
            sel = (run["time"] >= revolution * REVOLUTION) & (run["time"] < (revolution + 1) * REVOLUTION)
            deg = np.degrees(run["theta"][sel]) - 360.0 * revolution
            ax.plot(deg, run["slider_acceleration"][sel] * 1e-3, color=color, lw=lw,
                    label="dry" if label == "dry" else f"oil, {label}")  # fmt: skip
        ax.plot(np.degrees(theta), ideal_slider_acceleration(theta) * 1e-3, "k", lw=1.0, ls="--", label="ideal joint")
        ax.set(ylabel="slider acceleration (km/s$^2$)", xlim=(0, 360))
        ax.legend(fontsize=7)
    axes[0].set_title(f"Slider acceleration, revolution {revolution + 1}")
    axes[1].set_xlabel("crank angle (deg)")
    return fig


accelerations = plot_accelerations(runs)

if __name__ == "__main__" and "--save" in sys.argv:
    folder = sys.argv[sys.argv.index("--save") + 1]
    orbits.savefig(f"{folder}/lubricated_orbit.png", dpi=120, bbox_inches="tight")
    accelerations.savefig(f"{folder}/lubricated_acceleration.png", dpi=120, bbox_inches="tight")
elif __name__ == "__main__":
    plt.show()
