"""
Wear of the joint at E over operating hours
===========================================

Archard's law at the clearance joint: each step of a simulated revolution wears the bearing and the
journal by (k/H) F_N ds, spread over the contact arc; a few steady revolutions give the wear per
revolution, which is extrapolated over many revolutions until the clearance has grown by a set
fraction, the worn (no longer round) geometry is fed back into the contact, and so on (the page on
wear prediction gives the model and its sources). Here the reference loom at 400 rpm, starting from
c = 0.25 mm, for 20 operating hours with the default wear parameters (k = 1e-7, H = 2 GPa) and a coarse
update criterion (5 % clearance growth per update) to keep the example short. The shell command is
``weftsim wear reference --hours 20 --set joint_e.wear.max_clearance_change=0.05``.
"""

# %%
# Predict
# -------
# ``predict`` returns one record per geometry update: the hours and revolutions reached, the worn
# profiles (bearing in the rocker's frame, journal in the rod's) and the loom's response simulated on
# that geometry.
import weftsim
from weftsim.wear import predict
from weftsim.wear.store import table

scene = weftsim.load_scene("reference", {"joint_e.wear.max_clearance_change": 0.05})
updates = predict(scene, hours=20.0)
columns = table(scene, updates)
for hours, clearance, p99 in zip(columns["hours"], columns["effective_clearance_e_mm"],
                                 columns["contact_force_e_p99_N"]):
    print(f"{hours:7.2f} h   clearance {clearance:.4f} mm   99th percentile contact force {p99:8.0f} N")

# %%
# The worn profiles
# -----------------
# Each surface wears where the contact force presses on it, seen in its own body frame: the bearing
# (in the rocker) over two arcs, around 30 deg and 250 deg, the journal (in the rod) at 0 and 180 deg,
# along the rod's axis, which carries the joint's load in tension and in compression. The rod swings
# against the rocker, so the same load direction sweeps a wider arc of the bearing than of the journal.
from weftsim.wear.figures import growth_figure, profile_figure

profiles = profile_figure(scene, updates, title="Joint E, reference loom at 400 rpm")

# %%
# Clearance and response against hours
# -------------------------------------
# As the clearance grows the impacts grow harder: the 99th percentiles of the contact force and of the
# rapier acceleration rise with it, while the mean contact force (set by the mechanism's inertia loads)
# barely moves.
growth = growth_figure(columns, title="Growth with operating hours, 400 rpm")
