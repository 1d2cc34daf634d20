"""
The loom: one run and its channels
==================================

The bundled ``loom``: a rapier loom of 190 cm reed width (a spherical 4R, a parallelogram four-bar,
a sector gear, a light rapier wheel and the rapier band) at its nominal 600 rpm, with a new bushed pin
at joint E: 30 mm, 20 um radial clearance (docs/physics.md, "The loom mechanism"). Two revolutions on
the default engine (Exudyn), then the six channels of the second revolution and the orbit of the
journal centre inside the clearance circle. The same run from the shell is ``weftsim run loom``.
"""

# %%
# Load the scene and simulate
# ---------------------------
# ``"loom"`` names a scene bundled with weftsim (``weftsim.bundled_scenes()`` lists them; a path to
# a scene file works too). Overrides are given in the units of the scene file (mm, rpm, revolutions):
# ``weftsim.load_scene("loom", clearance_mm=0.25)`` is the same loom with a worn joint.
import weftsim

scene = weftsim.load_scene("loom")
result = weftsim.simulate(scene)
print(result.status, "on path:", result.path_text)
print(f"{result.solver_stats['steps']} accepted steps, {result.solver_stats['contact_events']} contact onsets, "
      f"first contact at crank angle {result.first_contact_angle_deg:.2f} deg")

# %%
# Peaks over the second revolution
# --------------------------------
# Peaks are taken at every accepted solver step (``result.steps``), not on the output grid
# (``result.samples``): an impact lasts about 0.1 ms and falls between output samples. Revolution 1
# starts from the centred journal, whose first impact (the start-up impact) is not the running loom's.
from weftsim.post.analysis import peaks

for name, value in peaks(result, 1).items():
    print(f"{name:28s} {value['min']:+12.5g} .. {value['max']:+12.5g}")

# %%
# The channels
# ------------
# Rapier displacement, velocity and acceleration, driving torque, contact force and penetration
# against the crank angle, like the paper's Fig. 12. At 20 um the pin bears on its bushing almost all
# the revolution: the curves are the ideal mechanism's (stroke 1.241 m, +-43 m/s, +-2133 m/s^2 at
# 600 rpm) but near 90 and 270 deg, where the force at E reverses and the journal crosses its
# clearance with a few small impacts.
from weftsim.post.plots import plot_channels, plot_orbit

channels = plot_channels([result])

# %%
# The journal in its clearance
# ----------------------------
# The eccentricity of the journal centre relative to the bearing centre at every solver step; on the
# circle ``|e| = c`` the journal touches the bearing. The journal starts centred, flies to the wall, and
# then alternates impacts (dots, coloured by impact velocity) with lasting contact, where it slides
# along the wall.
orbit = plot_orbit(result)
