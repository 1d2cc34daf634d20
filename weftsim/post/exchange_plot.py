"""The weft exchange's figure, ``exchange.png`` (no physics here: the channels of :mod:`weftsim.model.exchange`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from weftsim.post.results import RunResult

MAX_COLUMNS = 2  # the first transfer (start-up) and the last


def plot_exchange(result: RunResult) -> Figure:
    """One column per transfer window shown (the first and the last the run covers): both heads' positions in
    the shed (from the giver's outermost position) against the ideal mechanism's, their overlap, their relative
    speed's departure from the ideal and each head's position error against the ideal mechanism, over the
    window's crank angle."""
    from weftsim.mechanism.kinematics import linkage_state
    from weftsim.model.exchange import gap, head, transfers
    from weftsim.post.plots import clearance_label, figure

    scene, steps = result.scene, result.steps
    shown = transfers(scene, steps)
    shown = shown if len(shown) <= MAX_COLUMNS else [shown[0], shown[-1]]
    fig = figure(figsize=(5.2 * max(len(shown), 1), 10.0))
    axes = fig.subplots(4, max(len(shown), 1), sharex="col", squeeze=False)
    g = gap(scene)
    s_g, _ = head(steps)
    for column, transfer in enumerate(shown):
        low, high = transfer["window_crank_deg"]
        angle = steps["crank_angle_deg"]
        keep = (angle >= low) & (angle <= high)
        x = angle[keep] - 360.0 * (transfer["revolution"] - 1)
        ideal = linkage_state(np.radians(angle[keep]), scene.geometry)
        s_i, v_i = ideal.rapier_displacement, scene.drive.speed * ideal.d_rapier_displacement
        top, middle, speed, error = axes[:, column]
        top.plot(x, s_g[keep], color="tab:blue", label="giver head")
        top.plot(x, g - steps["taker_head_displacement_m"][keep], color="tab:red", label="taker head")
        top.plot(x, s_i, "k:", lw=0.8, label="ideal mechanism")
        top.plot(x, g - s_i, "k:", lw=0.8)
        top.set_ylabel("head position in the shed [m]")
        top.set_title(f"transfer {transfer['revolution']} (dead centre {transfer['dead_centre_crank_deg']:g} deg)")
        middle.plot(x, steps["exchange_overlap_m"][keep] * 1e3, color="tab:purple", label="overlap")
        middle.plot(x, (2.0 * s_i - g) * 1e3, "k:", lw=0.8, label="ideal")
        middle.set_ylabel("overlap of the heads [mm]")
        speed.plot(x, steps["exchange_relative_speed_m_s"][keep] - 2.0 * v_i, color="tab:green",
                   label="relative speed - ideal")
        speed.set_ylabel("relative speed error [m/s]")
        error.plot(x, steps["giver_head_error_m"][keep] * 1e3, color="tab:blue", label="giver")
        error.plot(x, steps["taker_head_error_m"][keep] * 1e3, color="tab:red", label="taker")
        error.set_ylabel("head error vs ideal [mm]")
        error.set_xlabel("crank angle in the revolution [deg]")
        for ax in (top, middle, speed, error):
            ax.axvline(transfer["dead_centre_crank_deg"] - 360.0 * (transfer["revolution"] - 1), color="0.6", lw=0.6)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    if not shown:
        axes[0, 0].text(0.5, 0.5, "no whole transfer window in the run", ha="center", transform=axes[0, 0].transAxes)
    taker = scene.exchange.taker_clearance if scene.exchange is not None else None
    taker_text = clearance_label(scene) if taker is None else f"c = {taker * 1e3:g} mm"
    rpm = scene.drive.speed * 60.0 / (2.0 * math.pi)
    fig.suptitle(f"{scene.name}, {result.engine} engine, {rpm:g} rpm: weft exchange, giver {clearance_label(scene)}, "
                 f"taker {taker_text}")
    fig.tight_layout()
    return fig
