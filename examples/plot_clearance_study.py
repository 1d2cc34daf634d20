"""
The paper's clearance study
===========================

The study of the paper's Fig. 12, short: the reference mechanism at 400 rpm with a radial clearance
at E of c = 0.01, 0.25 and 0.50 mm, and the ideal joint, over one revolution each on the reference
engine. A larger clearance lets the journal fly further before it strikes the bearing: the impacts
are harder, and the rapier acceleration and the driving torque move further from the ideal
mechanism's. ``weftsim study clearance`` is the full study (more revolutions, statistics, the
trend figures).
"""

# %%
# One run per clearance
# ---------------------
import weftsim
from weftsim.post.analysis import peaks

clearances_mm = (0.0, 0.01, 0.25, 0.5)
results = [weftsim.simulate(weftsim.load_scene("reference", clearance_mm=c, revolutions=1), engine="reference")
           for c in clearances_mm]

# %%
# Peaks of the first revolution
# -----------------------------
# The first revolution holds the start-up impact of the initially centred journal: its peaks are
# reproducible between engines and tolerances (later single-revolution peaks are not; see the
# physics, section 6).
print(f"{'c [mm]':>7s} {'max |a| [m/s2]':>15s} {'max |T| [N m]':>14s} {'max F_N [N]':>12s}")
for c, result in zip(clearances_mm, results):
    p = peaks(result, 0)
    print(f"{c:7.2f} {max(-p['rapier_acceleration_m_s2']['min'], p['rapier_acceleration_m_s2']['max']):15.1f} "
          f"{max(-p['driving_torque_Nm']['min'], p['driving_torque_Nm']['max']):14.1f} "
          f"{p['contact_force_N']['max']:12.1f}")

# %%
# The channels side by side
# -------------------------
from weftsim.post.plots import plot_channels

labels = ["ideal joint" if c == 0 else f"c = {c:g} mm" for c in clearances_mm]
figure = plot_channels(results, labels=labels, title="Clearance at E, 400 rpm, first revolution")
