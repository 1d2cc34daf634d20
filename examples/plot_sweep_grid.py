"""
A design sweep, loaded as a grid
================================

A sweep runs every combination of the varied scene keys, in parallel and resumably, into one
directory per cell, and tabulates the peaks of every cell in ``sweep.csv`` (see the page on design
sweeps). Here a small one: radial clearance c = 0.05, 0.25, 0.5 mm against crank speed
300, 500, 700 rpm, half a revolution per cell on the reference engine, 9 cells on 2 worker
processes. The shell command is ``weftsim sweep models/reference.toml --vary
clearance_mm=0.05,0.25,0.5 --vary speed_rpm=300:700:3 --set revolutions=0.5 --engine reference``.

The table is then read back as a labelled grid, peak against (clearance, speed), and drawn as a map.
"""

# %%
# Run the sweep
# -------------
import tempfile
from pathlib import Path

from weftsim.sweep import plan_sweep, run_sweep

# The repository's scene files, from its root or from examples/ (where the site's build runs this).
MODELS = Path("models") if Path("models").is_dir() else Path("../models")

plan = plan_sweep(MODELS / "reference.toml", ["clearance_mm=0.05,0.25,0.5", "speed_rpm=300:700:3"],
                  ["revolutions=0.5"], engine="reference")
outdir = Path(tempfile.mkdtemp(prefix="weftsim-sweep-"))
report = run_sweep(plan, outdir, jobs=2, progress=False)
print(f"{report.total} cells, {report.failed} failed; table {report.table.name}")

# %%
# Load the table as a grid
# ------------------------
# One row per cell; the varied keys are columns named by their short names. Reshaped onto the axes
# of the sweep, each peak column becomes a 2-D array indexed by (clearance, speed).
import csv

import numpy as np

with open(report.table, newline="") as file:
    rows = list(csv.DictReader(file))
clearances = sorted({float(r["clearance_mm"]) for r in rows})
speeds = sorted({float(r["speed_rpm"]) for r in rows})


def grid(column: str) -> np.ndarray:
    """The values of ``column`` on the (clearance, speed) grid; NaN where a cell failed."""
    values = np.full((len(clearances), len(speeds)), np.nan)
    for r in rows:
        if r["status"] == "success" and r[column]:
            values[clearances.index(float(r["clearance_mm"])), speeds.index(float(r["speed_rpm"]))] = float(r[column])
    return values


force = grid("contact_force_N_rev1_peak")
torque = grid("driving_torque_Nm_rev1_peak")
print("peak contact force over the first half revolution [N]; rows: c [mm], columns: speed [rpm]")
print("         " + "".join(f"{s:>10.0f}" for s in speeds))
for c, line in zip(clearances, force):
    print(f"{c:8.2f} " + "".join(f"{v:10.0f}" for v in line))

# %%
# The map
# -------
# The peak contact force rises with both the clearance (a longer free flight before the impact) and
# the speed (larger inertia loads pressing the journal against the bearing).
from matplotlib.figure import Figure

maps = Figure(figsize=(9, 3.8))
for ax, values, label in zip(maps.subplots(1, 2), (force, torque),
                             ("peak contact force [N]", "peak driving torque [N m]")):
    image = ax.imshow(values, origin="lower", aspect="auto", cmap="viridis")
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
