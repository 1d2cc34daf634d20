"""Figures (no physics here): matplotlib with the Agg backend, imported only when called."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Sequence
    from types import ModuleType

    from matplotlib.figure import Figure

    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult

PANELS = (
    ("rapier_displacement_m", "rapier displacement [mm]", 1e3),
    ("rapier_velocity_m_s", "rapier velocity [m/s]", 1.0),
    ("rapier_acceleration_m_s2", "rapier acceleration [m/s²]", 1.0),
    ("driving_torque_Nm", "driving torque [N·m]", 1.0),
    ("joint_force_N", "load of the joint at E [N]", 1.0),
    ("penetration_m", "penetration at E [mm]", 1e3),
)
# Added below PANELS when every curve has a clearance at F (weftsim.post.results.JOINT_F_CHANNELS).
PANELS_F = (
    ("joint_force_f_N", "load of the joint at F [N]", 1.0),
    ("penetration_f_m", "penetration at F [mm]", 1e3),
)


# Added when every curve has a lubricated joint E (weftsim.post.results.LUBRICATION_CHANNELS).
PANELS_LUBRICATION = (
    ("film_ratio", "film ratio h_min/σ at E", 1.0),
    ("film_force_N", "film force at E [N]", 1.0),
)


# Added when every curve has the flexible rapier tape (weftsim.post.results.TAPE_CHANNELS).
PANELS_TAPE = (
    ("head_acceleration_m_s2", "head acceleration [m/s²]", 1.0),
    ("tape_force_wheel_N", "tape force at the wheel [N]", 1.0),
)


def clearance_label(scene: Scene) -> str:
    """``c = 0.25 mm`` (clearance at E alone, as before), or the clearance of each joint: ``c_E = 0.25, c_F = 0.25 mm``."""
    if scene.joint_f.is_ideal:
        return f"c = {scene.joint.clearance * 1e3:g} mm"
    return f"c_E = {scene.joint.clearance * 1e3:g}, c_F = {scene.joint_f.clearance * 1e3:g} mm"


def figure(**options: Any) -> Figure:
    """A matplotlib Figure drawn by the Agg backend, without pyplot (whose import costs ~0.2 s of a
    ``weftsim run``); save it with :func:`weftsim.post.output.write_figure`."""
    from matplotlib.figure import Figure

    return Figure(**options)


def pyplot() -> ModuleType:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def last_revolution(result: RunResult) -> tuple[dict[str, np.ndarray], int]:
    """Per-step channels of the last complete revolution (all steps if the run is shorter)."""
    from weftsim.post.analysis import complete_revolutions

    steps = result.steps
    n = complete_revolutions(result)
    if n == 0:
        return steps, 0
    period = result.scene.drive.period
    t = steps["time_s"]
    keep = (t >= (n - 1) * period - 1e-12) & (t <= n * period + 1e-12)
    return {k: v[keep] for k, v in steps.items()}, n - 1


def channel_panels(curves: list[tuple], title: str, panels: tuple | None = None) -> Figure:
    """Six panels like the paper's Fig. 12/13/16 against crank angle over one revolution (eight when
    every curve has joint F's channels: its contact force and penetration below).

    Parameters
    ----------
    curves : list of (label, data, style)
        ``data`` holds per-step channels with ``crank_angle_deg`` folded to 0..360;
        ``style`` is a dict of matplotlib line options (may be empty).
    panels : tuple of (channel, axis label, scale), optional
        An even number of panels; default :data:`PANELS` (and :data:`PANELS_F`).  A curve without a
        panel's channel is left out of that panel.
    """
    if panels is None:
        panels = PANELS + (PANELS_F if curves and all("contact_force_f_N" in data for _, data, _ in curves) else ())
        panels += PANELS_LUBRICATION if curves and all("film_ratio" in data for _, data, _ in curves) else ()
        panels += PANELS_TAPE if curves and all(PANELS_TAPE[0][0] in data for _, data, _ in curves) else ()
    from weftsim.post.results import LOAD_FALLBACK

    rows = len(panels) // 2
    fig = figure(figsize=(11, 3 * rows))
    axes = fig.subplots(rows, 2, sharex=True)
    for label, data, style in curves:
        angle = data["crank_angle_deg"]
        for ax, (name, ylabel, scale) in zip(axes.flat, panels):
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
            values = data.get(name, data.get(LOAD_FALLBACK.get(name, "")))  # a 0.2 result: its dry law's load
            if values is None:
                continue
            ax.plot(angle, values * scale, label=label, rasterized=len(angle) > 20000,
                    **({"lw": 0.8} | style))
    for ax in axes[-1]:
        ax.set_xlabel("crank angle [deg]")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 60))
    axes.flat[0].legend(fontsize=8, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_channels(results: Sequence[RunResult], labels: Sequence[str] | None = None,
                  title: str | None = None) -> Figure:
    """Six panels over the last complete revolution of each result."""
    labels = labels or [f"{r.engine}, {clearance_label(r.scene)}, "
                        f"{r.scene.drive.speed * 30 / math.pi:g} rpm" for r in results]
    curves: list[tuple[str, dict[str, np.ndarray], dict[str, Any]]] = []
    for result, label in zip(results, labels):
        data, k = last_revolution(result)
        curves.append((label, {**data, "crank_angle_deg": data["crank_angle_deg"] - 360.0 * k}, {}))
    return channel_panels(curves, title or (results[0].scene.name + " (last revolution)"))


def plot_kinematics(angle_deg: np.ndarray, s: np.ndarray, v: np.ndarray, a: np.ndarray, title: str = "",
                    transmission_deg: np.ndarray | None = None) -> Figure:
    """Ideal rapier displacement, velocity and acceleration over one revolution, and with ``transmission_deg``
    the four-bar's transmission angle at F (90 deg is ideal; near 0 or 180 deg the four-bar is close to a dead point)."""
    panels = [(s * 1e3, "rapier displacement [mm]"), (v, "rapier velocity [m/s]"), (a, "rapier acceleration [m/s²]")]
    if transmission_deg is not None:
        panels.append((transmission_deg, "transmission angle at F [deg]"))
    fig = figure(figsize=(8, 2.7 * len(panels)))
    axes = fig.subplots(len(panels), 1, sharex=True)
    for ax, (y, label) in zip(axes, panels):
        ax.plot(angle_deg, y, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("crank angle [deg]")
    axes[-1].set_xlim(0, 360)
    axes[-1].set_xticks(range(0, 361, 60))
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def contact_onsets(steps: dict[str, np.ndarray]) -> np.ndarray:
    """Rows of the per-step channels that start a contact at E (an impact).

    A contact segment is where the engine holds an impact velocity (docs/physics.md section 2):
    :func:`weftsim.checks.plausibility.contact_mode`; an onset is its first row after free flight.
    """
    from weftsim.checks.plausibility import contact_mode, onset_rows

    return onset_rows(contact_mode(steps))


# A penetration above this fraction of the clearance is visible in the orbit: the panel says what it is.
PENETRATION_NOTE = 0.05

# The channels of each joint's orbit: eccentricity y, z and the held impact velocity (0 in free flight).
ORBIT_CHANNELS = {"e": ("eccentricity_y_m", "eccentricity_z_m", "impact_velocity_m_s"),
                  "f": ("eccentricity_f_y_m", "eccentricity_f_z_m", "impact_velocity_f_m_s")}


def plot_orbit(result: RunResult, title: str | None = None) -> Figure:
    """Orbit of the journal centre inside the clearance circle of each joint with a clearance, impacts marked.

    The eccentricity e = P_j - P_b (journal centre minus bearing centre, docs/physics.md
    section 2) is drawn at every accepted solver step in the four-bar plane (model y, z),
    inside the circle ``|e| = c`` of the radial clearance: on the circle the journal touches the
    bearing wall, outside it the two penetrate by ``δ = |e| - c``.  Each contact onset (an impact)
    is a dot coloured by its impact velocity δ̇⁻; the first is ringed.  The orbit of the journal
    centre is the standard picture of a clearance joint (as in Flores and Ambrósio 2004).  One panel
    per joint with a clearance: E, then F (its rod pin in the sector's eye, docs/clearance-f.md).

    Parameters
    ----------
    result : RunResult
        A run with a clearance joint (at E, at F or at both).
    title : str, optional
        Defaults to the scene, engine, clearance and crank speed.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    joints = [(name, joint) for name, joint in (("e", scene.joint), ("f", scene.joint_f))
              if joint.clearance > 0.0 and ORBIT_CHANNELS[name][0] in result.steps]
    if not joints:
        raise ValueError(f"the orbit needs a clearance joint: joint_e.clearance_mm must be > 0, got "
                         f"{scene.joint.clearance * 1e3:g} (or joint_f.clearance_mm > 0)")
    fig = figure(figsize=(6.4 * len(joints), 6.8))
    axes = np.atleast_1d(fig.subplots(1, len(joints)))
    rpm = scene.drive.speed * 30 / math.pi
    for ax, (name, joint) in zip(axes, joints):
        _orbit_panel(fig, ax, result.steps, ORBIT_CHANNELS[name], joint.clearance)
        ax.set_title(title or f"scene {scene.name}, engine {result.engine}:\njournal orbit at {name.upper()} "
                              f"(c = {joint.clearance * 1e3:g} mm, {rpm:g} rpm)", fontsize=10)
    fig.tight_layout()
    return fig


def _orbit_panel(fig, ax, steps: dict, channels: tuple[str, str, str], clearance: float) -> None:
    """One joint's orbit: its clearance circle, the journal centre at every step, and the impacts."""
    from weftsim.checks.plausibility import onset_rows

    ecc_y, ecc_z, impact = channels
    y_mm, z_mm = steps[ecc_y] * 1e3, steps[ecc_z] * 1e3
    onsets = onset_rows(np.asarray(steps[impact]) > 0.0)  # contact segments: v_imp held > 0 (contact_onsets)
    circle = np.linspace(0.0, 2.0 * math.pi, 361)
    c_mm = clearance * 1e3
    ax.plot(c_mm * np.cos(circle), c_mm * np.sin(circle), color="0.3", lw=1.2,
            label=f"clearance circle, c = {c_mm:g} mm")
    ax.plot(y_mm, z_mm, lw=0.6, color="tab:blue", label="journal centre (every solver step)",
            rasterized=len(y_mm) > 20000)
    if onsets.size:
        speed = steps[impact][onsets]
        dots = ax.scatter(y_mm[onsets], z_mm[onsets], c=speed, s=18, cmap="plasma", zorder=3,
                          label=f"impacts ({onsets.size}), colour = impact velocity")
        ax.scatter(y_mm[onsets[:1]], z_mm[onsets[:1]], s=90, facecolors="none", edgecolors="k", zorder=4,
                   label="first impact")
        fig.colorbar(dots, ax=ax, shrink=0.8, label="impact velocity δ̇⁻ [m/s]")
    ax.set_aspect("equal")
    beyond = float(np.max(np.hypot(y_mm, z_mm), initial=0.0)) - c_mm  # the largest penetration, mm
    if beyond > PENETRATION_NOTE * c_mm:  # a stiff joint of a small clearance: the orbit leaves the circle visibly
        ax.text(0.5, 0.98, f"drawn at true scale: the journal centre lies outside the circle by the contact's\n"
                f"penetration δ = |e| - c, up to {1e3 * beyond:.3g} µm = {beyond / c_mm:.2g} c (compliant contact)",
                transform=ax.transAxes, ha="center", va="top", fontsize=7,
                bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "0.7"})
    reach = 1.15 * max(c_mm, float(np.max(np.hypot(y_mm, z_mm), initial=0.0)))
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_xlabel("eccentricity y [mm]")
    ax.set_ylabel("eccentricity z [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
