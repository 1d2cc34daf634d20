"""The Stribeck figure of ``weftsim bearing``: friction coefficient against journal speed, the operating point marked.

No physics here: it draws the curve :func:`weftsim.joint.bearing.stribeck` computed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

REGIME_COLOURS = {"hydrodynamic": "tab:blue", "mixed": "tab:orange", "boundary": "tab:red"}


def plot_stribeck(report: dict) -> Figure:
    """Friction coefficient (log) against journal speed in rpm (log), coloured by regime, with the film ratio
    below; the operating point of the report's first point marked."""
    from weftsim.post.plots import figure

    curve = report["stribeck"]
    rpm = np.asarray(curve["journal_speed_rad_s"]) * 60.0 / (2.0 * math.pi)
    mu = np.asarray(curve["friction_coefficient"])
    ratio = np.maximum(np.asarray(curve["film_ratio"]), 1e-3)  # 0 once the dry law carries: at the foot
    fig = figure(figsize=(7.0, 6.0))
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": (2, 1)})
    top.loglog(rpm, mu, color="0.6", lw=1.0)
    for regime, colour in REGIME_COLOURS.items():
        mask = np.array([r == regime for r in curve["regime"]])
        if mask.any():
            top.loglog(rpm[mask], mu[mask], "o", ms=3.5, color=colour, label=regime)
    name, point = next(iter(report["points"].items()))
    op_rpm = point["journal_speed_rad_s"] * 60.0 / (2.0 * math.pi)
    top.loglog([op_rpm], [point["friction_coefficient"]], "k*", ms=12, label=f"{name} operating point")
    top.set_ylabel("friction coefficient f")
    oil = report["oil"] or f"{report['viscosity_mpa_s']:.4g} mPa s"
    top.set_title(f"{report['scene']}, joint {report['joint']}: W = {curve['load_n'] / 1e3:.4g} kN, {oil}")
    top.legend(fontsize=8)
    top.grid(True, which="both", alpha=0.3)
    bottom.loglog(rpm, ratio, color="k", lw=1.0)
    for level in (1.0, 3.0):
        bottom.axhline(level, color="0.5", ls="--", lw=0.8)
    bottom.axvline(op_rpm, color="k", ls=":", lw=0.8)
    bottom.set_xlabel("journal speed, rpm (bushing still)")
    bottom.set_ylabel("film ratio h_min / sigma")
    bottom.grid(True, which="both", alpha=0.3)
    return fig
