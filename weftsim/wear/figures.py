"""Figures of a wear prediction (no physics): the worn bearing as a polar plot over the hours, and the
clearance and the response against the hours.  matplotlib is imported only when called."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.plots import figure

if TYPE_CHECKING:
    from collections.abc import Sequence

    from matplotlib.figure import Figure

    from weftsim.params import Scene
    from weftsim.wear.extrapolate import Update


def _chosen(updates, count: int = 6):
    """About ``count`` updates spread over the run, first and last included."""
    idx = np.unique(np.linspace(0, len(updates) - 1, min(count, len(updates))).round().astype(int))
    return [updates[i] for i in idx]


def profile_figure(scene: Scene, updates: Sequence[Update], title: str = "") -> Figure:
    """Bearing clearance c0 + h_b(psi) (mm) and journal wear, polar, at several updates."""
    from matplotlib.ticker import MaxNLocator

    fig = figure(figsize=(10, 5))
    c0 = scene.joint.clearance * 1e3
    n = updates[0].bearing.size
    psi = np.append(np.arange(n), 0) * (2.0 * np.pi / n)
    for k, which in enumerate(("bearing", "journal")):
        ax = fig.add_subplot(1, 2, k + 1, projection="polar")
        radii = []
        for u in _chosen(updates):
            h = np.append(getattr(u, which), getattr(u, which)[0]) * 1e3
            radii.append((c0 if which == "bearing" else 0.0) + h)
            ax.plot(psi, radii[-1], label=f"{u.hours:.4g} h")
        ax.set_title(("bearing: c0 + h_b(psi) [mm], rocker frame" if which == "bearing"
                      else "journal: h_j(psi) [mm], rod frame"), fontsize=9, pad=14)
        ax.set_rlabel_position(label_angle(psi, np.max(radii, axis=0)))
        ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=7)
    # One legend for both panels, below them, inside the figure (drawn beside a polar axes it was clipped).
    handles, labels = fig.axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=8, frameon=False,
               title="operating hours", title_fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout(rect=(0.0, 0.1, 1.0, 1.0))
    return fig


def label_angle(psi: np.ndarray, radius: np.ndarray) -> float:
    """Angle, deg, for a polar panel's radial labels: where the curves stay closest to the centre (the labels
    then sit on empty ground, not on a lobe of the profile)."""
    candidates = np.arange(22.5, 360.0, 45.0)  # between the angle labels at every 45 deg
    reach = [np.max(radius[np.abs((np.degrees(psi) - a + 180.0) % 360.0 - 180.0) <= 22.5]) for a in candidates]
    return float(candidates[int(np.argmin(reach))])


def statistic_label(name: str) -> str:
    """``mean``, ``rms``, ``p99`` or ``max`` out of a ``wear.csv`` column name."""
    return next((word for word in ("mean", "rms", "p99", "max") if f"_{word}_" in name), name)


def growth_figure(columns: dict, title: str = "") -> Figure:
    """Effective clearance, contact force and rapier acceleration against operating hours (``wear.csv`` columns)."""
    fig = figure(figsize=(7, 8))
    hours = columns["hours"]
    panels = (("effective_clearance_mm", "effective clearance [mm]"),
              (("contact_force_mean_N", "contact_force_p99_N"), "contact force at E [N]"),
              (("rapier_acceleration_rms_m_s2", "rapier_acceleration_p99_m_s2"), "rapier acceleration [m/s²]"),
              (("driving_torque_rms_Nm", "driving_torque_p99_Nm"), "driving torque [N·m]"))
    for k, (names, label) in enumerate(panels):
        ax = fig.add_subplot(len(panels), 1, k + 1)
        for name in (names if isinstance(names, tuple) else (names,)):
            ax.plot(hours, columns[name], marker=".", label=statistic_label(name) if isinstance(names, tuple) else None)
        ax.set_ylabel(label, fontsize=8)
        if isinstance(names, tuple):
            ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
    fig.axes[-1].set_xlabel("operating hours")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
