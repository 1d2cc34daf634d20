"""Figures of a wear prediction (no physics): the worn bearing as a polar plot over the hours, and the
clearance and the response against the hours.  matplotlib is imported only when called."""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from weftsim.post.plots import figure

if TYPE_CHECKING:
    from collections.abc import Sequence

    from matplotlib.figure import Figure
    from matplotlib.projections.polar import PolarAxes

    from weftsim.input.params import Scene
    from weftsim.wear.extrapolate import Update


def conditions(scene: Scene, joints: Sequence[str] = ("e",)) -> str:
    """What a wear figure's numbers depend on, for its title: the speed and each joint's Archard k and
    hardnesses, bearing/journal (``600 rpm; E: k = 1e-07 (boundary), H 1670/6900 MPa``).

    k is the one the joint's solid contact wears with (its regime's, or the single ``wear_coefficient``
    that overrides the regimes); an oiled joint's asperities add theirs (``asperities 1e-07``)."""
    import math

    rpm = scene.drive.speed * 30.0 / math.pi
    parts = []
    for j in joints:
        joint = scene.joint if j == "e" else scene.joint_f
        w = joint.wear
        k = f"k = {w.contact_wear_coefficient:.3g}"
        if w.wear_coefficient is None:
            k += f" ({w.regime})"
        if joint.lubrication is not None:
            k += f", asperities {w.asperity_wear_coefficient:.3g}"
        parts.append(f"{j.upper()}: {k}, H {w.bearing_hardness / 1e6:g}/{w.journal_hardness / 1e6:g} MPa")
    return f"{rpm:g} rpm; " + "; ".join(parts)


def _chosen(updates, count: int = 6):
    """About ``count`` updates spread over the run, first and last included."""
    idx = np.unique(np.linspace(0, len(updates) - 1, min(count, len(updates))).round().astype(int))
    return [updates[i] for i in idx]


# The bodies whose frames the profiles are tabulated in (weftsim.physics.chain_f.local_clearances).
FRAMES = {"e": ("rocker", "rod"), "f": ("sector", "rod")}


def profile_figure(scene: Scene, updates: Sequence[Update], title: str = "", joint: str = "e") -> Figure:
    """Bearing clearance c0 + h_b(psi) (mm) and journal wear of ``joint``, polar, at several updates."""
    from matplotlib.ticker import MaxNLocator

    fig = figure(figsize=(10, 5))
    c0 = (scene.joint if joint == "e" else scene.joint_f).clearance * 1e3
    parts = [u.part(joint) for u in updates]
    n = parts[0].bearing.size
    psi = np.append(np.arange(n), 0) * (2.0 * np.pi / n)
    frames = FRAMES[joint]
    for k, which in enumerate(("bearing", "journal")):
        ax = cast("PolarAxes", fig.add_subplot(1, 2, k + 1, projection="polar"))
        radii = []
        for u in _chosen(list(zip(updates, parts))):
            u, part = u
            h = np.append(getattr(part, which), getattr(part, which)[0]) * 1e3
            radii.append((c0 if which == "bearing" else 0.0) + h)
            ax.plot(psi, radii[-1], label=f"{u.hours:.4g} h")
        ax.set_title((f"bearing at {joint.upper()}: c0 + h_b(psi) [mm], {frames[0]} frame" if which == "bearing"
                      else f"journal at {joint.upper()}: h_j(psi) [mm], {frames[1]} frame"), fontsize=9, pad=14)
        ax.set_rlabel_position(label_angle(psi, np.max(radii, axis=0)))
        ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=7)
        for label in ax.get_yticklabels():  # legible where a lobe of the profile still passes under a label
            label.set_bbox({"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.0})
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
    then sit on empty ground, not on a lobe of the profile).  Candidates every 15 deg off the 45 deg grid lines,
    each judged by the curves within 20 deg of it (a label is about that wide at mid radius)."""
    candidates = np.array([a for a in np.arange(7.5, 360.0, 15.0) if abs((a + 22.5) % 45.0 - 22.5) > 5.0])
    reach = [np.max(radius[np.abs((np.degrees(psi) - a + 180.0) % 360.0 - 180.0) <= 20.0]) for a in candidates]
    return float(candidates[int(np.argmin(reach))])


def statistic_label(name: str) -> str:
    """``mean``, ``rms``, ``p99`` or ``max`` out of a ``wear.csv`` column name."""
    word = next((word for word in ("mean", "rms", "p99", "max") if f"_{word}_" in name), None)
    joint = next((j for j in ("e", "f") if name.startswith(("effective_clearance_", "contact_force_"))
                  and f"_{j}_" in name), None)
    if word is None:
        return f"at {joint.upper()}" if joint else name
    return f"{word} at {joint.upper()}" if joint else word


def growth_figure(columns: dict, title: str = "", joints: Sequence[str] = ("e",),
                  limit_mm: float | None = None) -> Figure:
    """Effective clearance, the joint's load (film + asperities + dry law) and rapier acceleration against
    operating hours (``wear.csv`` columns), the clearance and load of each wearing joint; ``limit_mm``: the
    clearance limit, marked."""
    fig = figure(figsize=(7, 8))
    hours = columns["hours"]
    at = " and ".join(j.upper() for j in joints)
    panels = ((tuple(f"effective_clearance_{j}_mm" for j in joints), f"effective clearance at {at} [mm]"),
              (tuple(f"contact_force_{j}_{s}_N" for j in joints for s in ("mean", "p99")), f"load of the joint at {at} [N]"),
              (("rapier_acceleration_rms_m_s2", "rapier_acceleration_p99_m_s2"), "rapier acceleration [m/s²]"),
              (("driving_torque_rms_Nm", "driving_torque_p99_Nm"), "driving torque [N·m]"))
    for k, (names, label) in enumerate(panels):
        ax = fig.add_subplot(len(panels), 1, k + 1)
        for name in (names if isinstance(names, tuple) else (names,)):
            ax.plot(hours, columns[name], marker=".", label=statistic_label(name) if isinstance(names, tuple) else None)
        ax.set_ylabel(label, fontsize=8)
        if k == 0 and limit_mm is not None:
            ax.axhline(limit_mm, color="C3", ls="--", lw=1, label=f"limit {limit_mm:g} mm")
        if isinstance(names, tuple):
            ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
    fig.axes[-1].set_xlabel("operating hours [h]")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
