"""
A journal settling in its oil film
==================================

The oil film of :func:`weftsim.physics.film.film_force` carries a journal that spins in a still
bearing under a constant load. Started at the bearing centre, the journal sinks and swings
sideways (the film pushes back across the load as well as against it) until it rests where the
film's force balances the load: at an eccentricity ratio and an attitude angle (between the load
line and the line of centres) that depend on the load only through the Sommerfeld number
S = (R/c)^2 eta N / P (N the speed in rev/s, P the load per projected area D B).

Here a journal of radius 10 mm, 20 mm long (B/D = 1), with a radial clearance of 20 um in an oil
of 20 mPa s spins at 1500 rpm under the loads that make the Sommerfeld numbers of Raimondi and
Boyd's table (1958) for the finite bearing of B/D = 1. The journal is light (m c omega^2 / W =
0.05), so it follows the film's slow squeeze without whirling. Its resting points are drawn
against the table, with the short-bearing (Ocvirk) and long-bearing (Sommerfeld) models that the
multibody literature mostly uses beside the finite-length film.
"""

# %%
# The journal's motion
# --------------------
# Two degrees of freedom, the journal centre (y, z) relative to the bearing centre; the load W
# points down (-z). m y'' = F_y, m z'' = F_z - W with F the film force of the finite bearing.
import math

import numpy as np
from matplotlib.figure import Figure
from scipy.integrate import solve_ivp

from weftsim.physics.film import MODEL_FINITE, MODEL_LONG, MODEL_SHORT, film_force
from weftsim.joint.reynolds import RAIMONDI_BOYD, equilibrium, steady_load

RADIUS, LENGTH, CLEARANCE, VISCOSITY = 10e-3, 20e-3, 20e-6, 0.02  # m, m, m, Pa s
OMEGA = 2.0 * math.pi * 1500.0 / 60.0  # journal speed, rad/s; the bearing stands still
REVOLUTIONS = 60  # simulated time: long enough for the film's squeeze to settle


def settle(load):
    """Path of the journal centre (t, y, z) from the centre under a downward load, N."""
    mass = 0.05 * load / (CLEARANCE * OMEGA**2)

    def rhs(t, s):
        fy, fz, _, _ = film_force(s[0], s[1], s[2], s[3], OMEGA, 0.0, CLEARANCE, RADIUS, LENGTH, VISCOSITY,
                                  MODEL_FINITE)
        return [s[2], s[3], fy / mass, (fz - load) / mass]

    end = REVOLUTIONS * 2.0 * math.pi / OMEGA
    sol = solve_ivp(rhs, (0.0, end), [0.0, 0.0, 0.0, 0.0], method="Radau", rtol=1e-7,
                    atol=[1e-6 * CLEARANCE, 1e-6 * CLEARANCE, 1e-3 * CLEARANCE * OMEGA, 1e-3 * CLEARANCE * OMEGA])
    return sol.t, sol.y[0], sol.y[1]


table = RAIMONDI_BOYD[1.0]
speed = OMEGA / (2.0 * math.pi)
paths = []
print(" S       | eps: table  settled  | attitude: table  settled [deg]")
for eps_table, sommerfeld, attitude_table in table:
    load = (RADIUS / CLEARANCE) ** 2 * VISCOSITY * speed * (2.0 * RADIUS * LENGTH) / sommerfeld
    t, y, z = settle(load)
    eps_end = math.hypot(y[-1], z[-1]) / CLEARANCE
    attitude_end = math.degrees(math.atan2(y[-1], -z[-1]))  # from the load line (-z) to the line of centres
    paths.append((t, y, z, eps_table, attitude_table))
    print(f" {sommerfeld:<7.4g} | {eps_table:11.3f} {eps_end:8.3f}  | {attitude_table:15.2f} {attitude_end:8.2f}")

# %%
# The journal's paths in the clearance
# ------------------------------------
# Each path starts at the centre and ends on the table's resting point (rings), which lie on the
# curve of the finite-length equilibria (the finite bearing's steady loads, eps from 0 to 0.99).
locus = Figure(figsize=(5.8, 5.8))
ax = locus.subplots()
circle = np.linspace(0.0, 2.0 * np.pi, 361)
ax.plot(np.cos(circle), np.sin(circle), color="0.3", lw=1.0, label="clearance circle")
eps_curve = np.linspace(0.005, 0.99, 120)
attitude_curve = np.radians([steady_load(e, 1.0, MODEL_FINITE)[1] for e in eps_curve])
ax.plot(eps_curve * np.sin(attitude_curve), -eps_curve * np.cos(attitude_curve), color="0.55", lw=1.0, ls="--",
        label="finite-bearing equilibria")
for t, y, z, eps_table, attitude_table in paths:
    ax.plot(y / CLEARANCE, z / CLEARANCE, lw=0.9)
    a = math.radians(attitude_table)
    ax.plot(eps_table * math.sin(a), -eps_table * math.cos(a), "o", mfc="none", mec="k", ms=7)
ax.plot([], [], "o", mfc="none", mec="k", label="Raimondi & Boyd (1958), B/D = 1")
ax.annotate("load", xy=(-0.6, -0.1), xytext=(-0.6, 0.4), ha="center",
            arrowprops={"arrowstyle": "->", "color": "0.4"}, color="0.4")
ax.set_aspect("equal")
ax.set_xlabel("y / c")
ax.set_ylabel("z / c")
ax.set_title("journal centre, 1500 rpm, spinning counter-clockwise", fontsize=9)
ax.legend(fontsize=8, loc="upper right")
ax.grid(alpha=0.3)
locus.tight_layout()

# %%
# Sommerfeld number and attitude angle against the table
# ------------------------------------------------------
# The finite-length film against Raimondi and Boyd's values at B/D = 1 and 1/2, and the two
# approximations: the short bearing overestimates the load (lower S at the same eccentricity) by
# 1.7x at eps = 0.5 and 5.7x at 0.9 for B/D = 1; the long bearing (half-Sommerfeld) misses the side
# leakage the other way.
chart = Figure(figsize=(9.0, 4.2))
ax1, ax2 = chart.subplots(1, 2)
eps_line = np.linspace(0.05, 0.98, 60)
for width, colour in ((1.0, "C0"), (0.5, "C1")):
    for model, style, name in ((MODEL_FINITE, "-", "finite"), (MODEL_SHORT, ":", "short"), (MODEL_LONG, "--", "long")):
        values = np.array([steady_load(e, width, model) for e in eps_line])
        ax1.loglog(values[:, 0], eps_line, style, color=colour, lw=1.0, label=f"{name}, B/D = {width:g}")
        if model == MODEL_FINITE:
            ax2.plot(eps_line, values[:, 1], style, color=colour, lw=1.0, label=f"{name}, B/D = {width:g}")
    rows = np.array(RAIMONDI_BOYD[width])
    ax1.plot(rows[:, 1], rows[:, 0], "o", mfc="none", mec=colour, label=f"Raimondi & Boyd, B/D = {width:g}")
    ax2.plot(rows[:, 0], rows[:, 2], "o", mfc="none", mec=colour, label=f"Raimondi & Boyd, B/D = {width:g}")
ax1.set_xlabel("Sommerfeld number S")
ax1.set_ylabel("eccentricity ratio")
ax1.set_ylim(0.04, 1.0)
ax1.legend(fontsize=6, ncol=2)
ax2.set_xlabel("eccentricity ratio")
ax2.set_ylabel("attitude angle [deg]")
ax2.legend(fontsize=7)
for axis in (ax1, ax2):
    axis.grid(alpha=0.3, which="both")
chart.tight_layout()

# %%
# The same equilibria by root finding
# -----------------------------------
# :func:`weftsim.joint.reynolds.equilibrium` solves F(eps) = W directly; the dynamic runs above end there.
for width, rows in RAIMONDI_BOYD.items():
    for eps_table, sommerfeld, attitude_table in rows:
        eps, attitude = equilibrium(sommerfeld, width, MODEL_FINITE)
        print(f"B/D = {width:g}, S = {sommerfeld:<7.4g}: eps {eps:.3f} (table {eps_table}), "
              f"attitude {attitude:.2f} deg (table {attitude_table})")
