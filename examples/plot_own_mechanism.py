"""
Your own mechanism: a variant of the loom from Python
=====================================================

A designer's first question is rarely the bundled loom itself but a machine like it: here a narrower
loom, 150 cm of reed instead of 190 cm, built from the bundled ``loom`` by overriding scene keys (in the
scene file's units) rather than by writing a file. The example checks the variant's plausibility before
running it, simulates it next to the bundled loom, reads the checks of the runs, and shows what a worn pin
does to the same checks. The how-to page "Your own mechanism" explains each key used here; the same
variant from the shell is ``weftsim run loom --set mechanism.rapier_gear_pitch_radius_mm=118.4 ...``.
"""

# %%
# The variant: change the keys that differ
# ----------------------------------------
# The rapier's stroke is (d5 d7 / d6) times the swing of the sector (docs/physics.md section 1), so a
# narrower loom with the same linkage needs a smaller rapier gear d7, in the ratio of the strokes; the
# rapier band is shorter and lighter in the same ratio. Every other key is the bundled loom's.
import numpy as np

import weftsim
from weftsim.mechanism.kinematics import rapier_motion

ratio = 150.0 / 190.0  # reed width of the variant over the loom's
overrides = {
    "mechanism.rapier_gear_pitch_radius_mm": round(150.0 * ratio, 1),  # d7 of the loom: 150 mm
    "inertia.rapier_mass_kg": round(0.35 * ratio, 3),  # the loom's band and head: 0.35 kg
}
loom = weftsim.load_scene("loom")
variant = weftsim.load_scene("loom", overrides=overrides)

theta = np.linspace(0.0, 2.0 * np.pi, 1441)  # one crank revolution, 0.25 deg apart
for name, scene in (("loom", loom), ("variant", variant)):
    s, v, a = rapier_motion(theta, scene.drive.speed, scene.geometry)
    print(f"{name:8s} stroke {s.max() - s.min():.3f} m, peak speed {np.abs(v).max():.1f} m/s, "
          f"peak acceleration {np.abs(a).max():.0f} m/s^2 (ideal mechanism, {scene.drive.speed * 30 / np.pi:.0f} rpm)")

# %%
# Plausible before it runs?
# -------------------------
# ``weftsim.plausibility_checks`` judges the scene from the ideal mechanism, without a simulation: the
# mass reflected to the pin, the clearance over the pin diameter, the pin pressure and p x v against the
# bushing's ratings, the Hertz pressure and the rapier's acceleration (docs/plausibility.md). Each check
# names the scene key that sets its limit; ``verdict`` is ``ok``, ``warning``, ``no_limit`` (the scene
# gives no limit) or ``info`` (a number that is only reported).


def show(checks):
    for check in checks:
        limit = check["limit"]
        limit = "-" if limit is None else (f"{limit[0]:.4g}..{limit[1]:.4g}" if isinstance(limit, list)
                                           else f"{limit:.4g}")
        print(f"  {check['stage']:6s} {check['name']:20s} {check['value']:11.4g} {check['unit'] if check['unit'] != '1' else '':8s} "
              f"limit {limit:16s} {check['verdict']}")


print("variant, before the run:")
show(weftsim.plausibility_checks(variant))

# %%
# Run both, and read the checks of the runs
# -----------------------------------------
# Two revolutions each (the scenes' ``drive.revolutions``) on the reference engine, the faster of the two
# for a single run. After a run, ``result.plausibility["checks"]`` holds the checks again, now from the
# run's own contact forces and accelerations (revolution 2, after the start-up impact of the centred
# journal), and ``result.plausibility["warnings"]`` the lines ``weftsim run`` would print.
results = {}
for name, scene in (("loom", loom), ("variant", variant)):
    results[name] = weftsim.simulate(scene, "reference", on_warning=print)
    print(f"{name}: {results[name].status}, warnings: {results[name].plausibility['warnings'] or 'none'}")
print("variant, after the run:")
show([check for check in results["variant"].plausibility["checks"] if check["stage"] == "after"])

# %%
# A worn pin in the variant
# -------------------------
# The same variant with the pin worn to 0.1 mm radial clearance (``clearance_mm`` is the shorthand of
# ``joint_e.clearance_mm``). Now the checks warn: the clearance is far outside the design range of a
# bushed pin, and the impacts through the clearance multiply the rapier's acceleration beyond what a
# rapier head is built for. Each warning names the key to change.
worn = weftsim.load_scene("loom", overrides=overrides, clearance_mm=0.1)
messages = []
results["variant, c = 0.1 mm"] = weftsim.simulate(worn, "reference", on_warning=messages.append)
for line in messages + results["variant, c = 0.1 mm"].plausibility["warnings"]:
    print("warning:", line)

# %%
# The three runs side by side
# ---------------------------
# The channels of the last revolution: the narrower loom's smaller stroke and acceleration, and the
# worn pin's impacts near 90 and 270 deg, where the force at E reverses.
from weftsim.post.plots import plot_channels

channels = plot_channels(list(results.values()), labels=list(results),
                         title="the loom, its 150 cm variant and the variant with a worn pin (last revolution)")
