"""Sweep figures (no physics here): peaks across a 1-D grid (lines) or a 2-D grid (heat maps).

Rows are those of :func:`weftsim.sweep.store.collect_rows`.  Failed or missing
cells are left blank (grey in a heat map, a gap in a line).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from weftsim.sweep.cell import METRIC_CHANNELS

if TYPE_CHECKING:
    from matplotlib.figure import Figure

PANEL_LABELS = {
    "driving_torque_Nm": "peak |driving torque| [N·m]",
    "rapier_acceleration_m_s2": "peak |rapier acceleration| [m/s²]",
    "contact_force_N": "peak contact force at E [kN]",
    "contact_force_f_N": "peak contact force at F [kN]",
    "joint_force_N": "peak load of the joint at E [kN]",
    "joint_force_f_N": "peak load of the joint at F [kN]",
}
# Forces reach 1e5 N: shown in kN.
SCALES = {"contact_force_N": 1e-3, "contact_force_f_N": 1e-3, "joint_force_N": 1e-3, "joint_force_f_N": 1e-3}
# The panels: torque, acceleration and the load of each joint (the film and asperity columns stay in the table).
PLOTTED_CHANNELS = ("driving_torque_Nm", "rapier_acceleration_m_s2", "joint_force_N", "joint_force_f_N")


UNITS = {"mm": "mm", "rpm": "rpm", "deg": "deg", "gpa": "GPa", "kg": "kg", "s": "s", "kg_m2": "kg m²"}


def axis_label(name: str) -> str:
    """``clearance_mm`` -> ``clearance [mm]``; names without a known unit suffix stay as they are."""
    for suffix in sorted(UNITS, key=len, reverse=True):
        if name.endswith("_" + suffix):
            return f"{name[: -len(suffix) - 1].replace('_', ' ')} [{UNITS[suffix]}]"
    return name


def _short(value: float) -> str:
    """Three digits, thousands as k: 2.02k, 870k."""
    return f"{value:.3g}" if abs(value) < 1e3 else f"{value / 1e3:.3g}k"


def _number(value) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        return math.nan
    return out if math.isfinite(out) else math.nan


def _axis_values(rows: list[dict], name: str) -> tuple[list, bool]:
    """Distinct values of one parameter, sorted; and whether they are all numbers."""
    values = list(dict.fromkeys(row[name] for row in rows))
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
    return (sorted(values) if numeric else sorted(values, key=str)), numeric


def _value(row: dict, channel: str, which: str) -> float:
    return _number(row.get(f"{channel}_{which}_peak")) if row.get("status") == "success" else math.nan


def shown_channels(rows: list[dict]) -> tuple[str, ...]:
    """The panels to draw: torque and acceleration always, the load of each joint with a clearance
    in some successful cell (a joint ideal in every cell has no contact force to show)."""
    def present(channel: str) -> bool:
        return any(math.isfinite(_value(row, channel, "rev1")) for row in rows)

    loads = ("joint_force_N", "joint_force_f_N")
    if not any(present(c) for c in loads):  # a table written before the load columns existed
        return tuple(c for c in METRIC_CHANNELS[:4] if c not in ("contact_force_N", "contact_force_f_N") or present(c))
    return tuple(c for c in PLOTTED_CHANNELS if c not in loads or present(c))


def _edges(centres: np.ndarray, numeric: bool = False) -> np.ndarray:
    """Cell edges half-way between centres (ends mirrored), so uneven grids draw honestly.

    For ``numeric`` values that are all >= 0 (a clearance, a speed) no cell reaches below 0: a mirrored
    first edge would put the axis at -0.1 mm for clearances 0.01, 0.25, 0.5 mm, a value no run had.
    """
    if centres.size == 1:
        half = 0.5 if not numeric or centres[0] == 0 else 0.5 * abs(centres[0])
        edges = np.array([centres[0] - half, centres[0] + half])
    else:
        mid = 0.5 * (centres[1:] + centres[:-1])
        edges = np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])
    if numeric and centres.min() >= 0.0:
        edges[0] = max(edges[0], 0.0)
    return edges


def windows(rows: list[dict]) -> list[tuple[str, str]]:
    """Which peaks to draw: the first revolution, and the last one when some run has more than one."""
    last = max((int(_number(r.get("last_revolution"))) for r in rows
                if r.get("status") == "success" and math.isfinite(_number(r.get("last_revolution")))), default=1)
    first = [("rev1", "first revolution")]
    return first + [("last", f"last revolution ({last})" if last > 1 else "last revolution")] if last > 1 else first


def _grid_panel(fig, ax, grid, xc, yc, channel, annotate, numeric=(False, False)):
    ax.set_facecolor("0.85")  # failed or missing cells show as grey
    scale = SCALES.get(channel, 1.0)
    xe, ye = _edges(xc, numeric[0]), _edges(yc, numeric[1])
    mesh = ax.pcolormesh(xe, ye, np.ma.masked_invalid(grid * scale), cmap="viridis", shading="flat")
    ax.set_xlim(xe[0], xe[-1])  # the axes span the cells, no more (limits from the data)
    ax.set_ylim(ye[0], ye[-1])
    xt, yt = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])  # labels in the middle of their cells
    fig.colorbar(mesh, ax=ax, label=PANEL_LABELS[channel])
    if annotate and np.isfinite(grid).any():
        top = np.nanmax(grid)
        for i in range(grid.shape[0]):
            for j in range(grid.shape[1]):
                if np.isfinite(grid[i, j]):
                    ax.text(xt[j], yt[i], _short(grid[i, j] * scale), ha="center", va="center", fontsize=7,
                            color="white" if grid[i, j] < 0.6 * top else "black")


def plot_sweep_1d(rows: list[dict], name: str, title: str = "") -> Figure:
    """Panels of peak torque, acceleration and the contact force of each clearance joint (E, F) against
    the varied parameter."""
    from weftsim.post.plots import pyplot

    plt = pyplot()
    values, numeric = _axis_values(rows, name)
    x = np.array(values, dtype=float) if numeric else np.arange(len(values), dtype=float)
    by_value = {row[name]: row for row in rows}
    channels = shown_channels(rows)
    fig, axes = plt.subplots(1, len(channels), figsize=(4.4 * len(channels), 3.8), squeeze=False)
    axes = axes[0]
    for ax, channel in zip(axes, channels):
        for (which, label), style in zip(windows(rows), ("o-", "s--")):
            y = np.array([_value(by_value[v], channel, which) for v in values]) * SCALES.get(channel, 1.0)
            ax.plot(x, y, style, ms=4, lw=1, label=label)
        ax.set_xlabel(axis_label(name))
        ax.set_ylabel(PANEL_LABELS[channel])
        if not numeric:
            ax.set_xticks(x, [str(v) for v in values], rotation=30)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_sweep_2d(rows: list[dict], x_name: str, y_name: str, title: str = "") -> Figure:
    """Heat maps of peak torque, acceleration and each clearance joint's contact force over the (x, y) grid.

    One row for the first revolution and, when the runs are longer, one for the last
    complete revolution; values are written into the cells of small grids.
    """
    from weftsim.post.plots import pyplot

    plt = pyplot()
    xs, x_numeric = _axis_values(rows, x_name)
    ys, y_numeric = _axis_values(rows, y_name)
    xc = np.array(xs, dtype=float) if x_numeric else np.arange(len(xs), dtype=float)
    yc = np.array(ys, dtype=float) if y_numeric else np.arange(len(ys), dtype=float)
    index = {(row[x_name], row[y_name]): row for row in rows}
    shown = windows(rows)
    channels = shown_channels(rows)
    fig, axes = plt.subplots(len(shown), len(channels), figsize=(5 * len(channels), 4.2 * len(shown)),
                             constrained_layout=True, squeeze=False)
    for (which, label), axes_row in zip(shown, axes):
        for ax, channel in zip(axes_row, channels):
            grid = np.full((len(ys), len(xs)), np.nan)
            for i, yv in enumerate(ys):
                for j, xv in enumerate(xs):
                    if (xv, yv) in index:
                        grid[i, j] = _value(index[(xv, yv)], channel, which)
            _grid_panel(fig, ax, grid, xc, yc, channel, annotate=len(xs) * len(ys) <= 80,
                        numeric=(x_numeric, y_numeric))
            ax.set_title(label, fontsize=10)
            ax.set_xlabel(axis_label(x_name))
            ax.set_ylabel(axis_label(y_name))
            if not x_numeric:
                ax.set_xticks(xc, [str(v) for v in xs], rotation=30)
            elif len(xs) <= 12:  # a tick at each value run
                ax.set_xticks(xc, [f"{v:g}" for v in xs])
            if not y_numeric:
                ax.set_yticks(yc, [str(v) for v in ys])
            elif len(ys) <= 12:
                ax.set_yticks(yc, [f"{v:g}" for v in ys])
    fig.suptitle(title)
    return fig


def plot_sweep(rows: list[dict], axis_names: list[str], title: str = "") -> Figure | None:
    """The figure for a 1-D or 2-D sweep, or None for more axes (the table still has every cell)."""
    if not any(row.get("status") == "success" for row in rows):
        return None
    if len(axis_names) == 1:
        return plot_sweep_1d(rows, axis_names[0], title)
    if len(axis_names) == 2:
        return plot_sweep_2d(rows, axis_names[0], axis_names[1], title)
    return None
