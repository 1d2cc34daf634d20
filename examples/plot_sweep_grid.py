"""
A design sweep, loaded as a grid
================================

A sweep runs every combination of the varied scene keys, in parallel and resumably, into one
directory per cell, and tabulates the peaks of every cell in ``sweep.csv`` (see the page on design
sweeps). Here a small one: radial clearance c = 0.05, 0.25, 0.5 mm against crank speed
300, 500, 700 rpm, half a revolution per cell on the reference engine, 9 cells on 2 worker
processes. The shell command is ``weftsim sweep reference --vary
clearance_mm=0.05,0.25,0.5 --vary speed_rpm=300:700:3 --set revolutions=0.5 --engine reference``.

The table is then read back as a labelled grid, peak against (clearance, speed), and drawn as a map.
"""

# %%
# Run the sweep
# -------------
import tempfile
from pathlib import Path

from weftsim.sweep import plan_sweep, run_sweep

plan = plan_sweep("reference", ["clearance_mm=0.05,0.25,0.5", "speed_rpm=300:700:3"],
                  ["revolutions=0.5"], engine="reference")
outdir = Path(tempfile.mkdtemp(prefix="weftsim-sweep-"))
report = run_sweep(plan, outdir, jobs=2, progress=False)
print(f"{report.total} cells, {report.failed} failed; table {report.table.name}")

# %%
# Load the sweep as a labelled grid
# ---------------------------------
# ``weftsim.load_sweep`` reads the sweep directory as an :class:`xarray.Dataset` (xarray comes with the
# optional extra ``weftsim[data]``): one dimension per varied key, named as in the cell names, with its
# values in file units as coordinates; each column of ``sweep.csv`` is a variable on that grid, NaN where
# a cell failed or was not run.
import weftsim

grid = weftsim.load_sweep(outdir)
print(grid)
force = grid["contact_force_N_rev1_peak"]
torque = grid["driving_torque_Nm_rev1_peak"]
print("peak contact force over the first half revolution [N]; rows: c [mm], columns: speed [rpm]")
print(force.to_pandas().round(0))

# %%
# The map
# -------
# The peak contact force rises with both the clearance (a longer free flight before the impact) and
# the speed (larger inertia loads pressing the journal against the bearing).
from matplotlib.figure import Figure

maps = Figure(figsize=(9, 3.8))
clearances, speeds = grid["clearance_mm"].values, grid["speed_rpm"].values
for ax, values, label in zip(maps.subplots(1, 2), (force, torque),
                             ("peak contact force [N]", "peak driving torque [N m]")):
    image = ax.imshow(values.transpose("clearance_mm", "speed_rpm").values, origin="lower", aspect="auto",
                      cmap="viridis")
    ax.set_xticks(range(len(speeds)), [f"{s:g}" for s in speeds])
    ax.set_yticks(range(len(clearances)), [f"{c:g}" for c in clearances])
    ax.set_xlabel("crank speed [rpm]")
    ax.set_ylabel("clearance c [mm]")
    maps.colorbar(image, ax=ax, label=label)
maps.suptitle("First half revolution, reference engine")
maps.tight_layout()

# %%
# The sweep's directory was temporary; a real sweep keeps it, and rerunning the same command skips
# its finished cells.
import shutil

shutil.rmtree(outdir)
