"""Figures (no physics here): matplotlib with the Agg backend, imported only when called."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from types import ModuleType

    from matplotlib.figure import Figure

PANELS = (
    ("rapier_displacement_m", "rapier displacement [mm]", 1e3),
    ("rapier_velocity_m_s", "rapier velocity [m/s]", 1.0),
    ("rapier_acceleration_m_s2", "rapier acceleration [m/s²]", 1.0),
    ("driving_torque_Nm", "driving torque [N·m]", 1.0),
    ("contact_force_N", "contact force at E [N]", 1.0),
    ("penetration_m", "penetration at E [mm]", 1e3),
)


def figure(**options) -> Figure:
    """A matplotlib Figure drawn by the Agg backend, without pyplot (whose import costs ~0.2 s of a
    ``weftsim run``); save it with :func:`weftsim.output.write_figure`."""
    from matplotlib.figure import Figure

    return Figure(**options)


def pyplot() -> ModuleType:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def last_revolution(result) -> tuple[dict[str, np.ndarray], int]:
    """Per-step channels of the last complete revolution (all steps if the run is shorter)."""
    from weftsim.analysis import complete_revolutions

    steps = result.steps
    n = complete_revolutions(result)
    if n == 0:
        return steps, 0
    period = result.scene.drive.period
    t = steps["time_s"]
    keep = (t >= (n - 1) * period - 1e-12) & (t <= n * period + 1e-12)
    return {k: v[keep] for k, v in steps.items()}, n - 1


def channel_panels(curves, title: str) -> Figure:
    """Six panels like the paper's Fig. 12/13/16 against crank angle over one revolution.

    Parameters
    ----------
    curves : list of (label, data, style)
        ``data`` holds per-step channels with ``crank_angle_deg`` folded to 0..360;
        ``style`` is a dict of matplotlib line options (may be empty).
    """
    fig = figure(figsize=(11, 9))
    axes = fig.subplots(3, 2, sharex=True)
    for label, data, style in curves:
        angle = data["crank_angle_deg"]
        for ax, (name, ylabel, scale) in zip(axes.flat, PANELS):
            ax.plot(angle, data[name] * scale, label=label, rasterized=len(angle) > 20000,
                    **({"lw": 0.8} | style))
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("crank angle [deg]")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 60))
    axes.flat[0].legend(fontsize=8, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_channels(results, labels=None, title=None) -> Figure:
    """Six panels over the last complete revolution of each result."""
    labels = labels or [f"{r.engine}, c = {r.scene.joint.clearance * 1e3:g} mm, "
                        f"{r.scene.drive.speed * 30 / math.pi:g} rpm" for r in results]
    curves = []
    for result, label in zip(results, labels):
        data, k = last_revolution(result)
        curves.append((label, {**data, "crank_angle_deg": data["crank_angle_deg"] - 360.0 * k}, {}))
    return channel_panels(curves, title or (results[0].scene.name + " (last revolution)"))


def plot_kinematics(angle_deg, s, v, a, title="") -> Figure:
    """Ideal rapier displacement, velocity and acceleration over one revolution."""
    fig = figure(figsize=(8, 8))
    axes = fig.subplots(3, 1, sharex=True)
    for ax, y, label in zip(axes, (s * 1e3, v, a), ("displacement [mm]", "velocity [m/s]", "acceleration [m/s²]")):
        ax.plot(angle_deg, y, lw=1.2)
        ax.set_ylabel("rapier " + label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("crank angle [deg]")
    axes[-1].set_xlim(0, 360)
    axes[-1].set_xticks(range(0, 361, 60))
    fig.suptitle(title)
    fig.tight_layout()
    return fig
