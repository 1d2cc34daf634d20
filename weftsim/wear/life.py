"""The life report of a wear ensemble: calendar time to the limit and the stop-starts' share of the wear
(docs/wear.md section 12).

The ensemble (:mod:`weftsim.wear.ensemble`) gives each sample's running hours to every clearance level.  A
planner reads calendar time: each sample's hours are turned into calendar days by its own duty cycle
(:meth:`weftsim.input.params.Duty.calendar_days`, the ``[duty]`` keys the sample draws or the scene's), and the
days are summarised as the hours are (p10 / p50 / p90 with their order-statistic intervals, censored samples
beyond the horizon's days).  The stop-starts' share of the worn volume is each design prediction's
(:func:`prediction_stop_share`): it is a property of the simulated design points, reported per point.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from weftsim.input.params import Scene

DUTY_KEYS = ("stops_per_hour", "stop_minutes", "hours_per_day", "days_per_week")
SHIFTS = (8.0, 16.0, 24.0)  # hours a day of one, two and three shifts


def sample_days(scene: Scene, values: dict[str, np.ndarray], hours: np.ndarray) -> np.ndarray:
    """Calendar days of each sample's ``hours`` (samples, levels), inf where the hours are: the duty of each
    sample (its drawn ``duty.*`` values, the scene's otherwise)."""
    duty = scene.duty
    n = hours.shape[0]
    keys = {name: np.asarray(values.get(f"duty.{name}", np.full(n, getattr(duty, name))), dtype=float)
            for name in DUTY_KEYS}
    scheduled = 1.0 + keys["stops_per_hour"] * keys["stop_minutes"] / 60.0
    factor = scheduled / keys["hours_per_day"] * 7.0 / keys["days_per_week"]
    return hours * factor[:, None]


def shift_days(scene: Scene, values: dict[str, np.ndarray], hours: np.ndarray) -> dict[float, np.ndarray] | None:
    """{hours a day: calendar days of each sample's ``hours``} at one, two and three shifts (:data:`SHIFTS`), the
    other duty keys as in :func:`sample_days`; None where ``duty.hours_per_day`` is drawn (the samples' own
    shifts are then the report's calendar days)."""
    if "duty.hours_per_day" in values:
        return None
    n = hours.shape[0]
    return {h: sample_days(scene, {**values, "duty.hours_per_day": np.full(n, h)}, hours) for h in SHIFTS}


def horizon_days(scene: Scene, values: dict[str, np.ndarray], horizon: float, hours_per_day: float | None = None
                 ) -> float:
    """The horizon in calendar days, what a censored calendar quantile lies beyond: the least of the samples'
    days at ``horizon`` running hours (each sample's own duty, as :func:`sample_days`; at ``hours_per_day``
    where given).  A sample that does not reach a level within the horizon is beyond its own horizon's days, and
    these differ where ``duty.*`` keys are drawn (15 stops an hour at 2.87 min each make an hour of running 1.72
    scheduled hours, 5 stops 1.24): only the least of them bounds every censored sample."""
    if hours_per_day is not None:
        values = {**values, "duty.hours_per_day": np.full(1, hours_per_day)}
    n = max([1] + [np.size(v) for v in values.values()])
    return float(np.min(sample_days(scene, values, np.full((n, 1), horizon))))


def prediction_stop_share(updates: list, joint: str = "e") -> float | None:
    """The stop-starts' share of the volume a prediction's ``updates`` wear (N-weighted over the updates; None
    when nothing wears or the duty has no stops)."""
    volume = share = 0.0
    for u in updates:
        v = u.step_revolutions * u.part(joint).volume_rate
        s = u.response.get(f"stop_start_share_{joint}", math.nan)
        if v > 0.0 and math.isfinite(s):
            volume += v
            share += v * s
    return share / volume if volume > 0.0 else None


def stop_share_summary(results: dict, centre: str = "centre") -> dict | None:
    """{"centre", "min", "median", "max"} of the design predictions' stop-start shares (None without stops);
    ``centre``: the job name of the centre design point (:func:`weftsim.wear.ensemble_design.centre_name`)."""
    shares = {n: r.get("stop_start_share") for n, r in results.items() if r.get("stop_start_share") is not None}
    if not shares:
        return None
    values = np.array(list(shares.values()), dtype=float)
    return {"centre": shares.get(centre), "min": float(values.min()), "median": float(np.median(values)),
            "max": float(values.max()), "by_design_point": dict(sorted(shares.items()))}


def life_figure(days: np.ndarray, levels_mm: list[float], data: dict, title: str = "") -> Figure:
    """Left: the distribution of the calendar days to each clearance level (its curve ends at the fraction of
    the samples reaching it within the horizon); right: the stop-starts' share of the wear at each design point."""
    from weftsim.post.plots import figure

    fig = figure(figsize=(11, 4.2))
    ax = fig.add_subplot(1, 2, 1)
    for i, level in enumerate(levels_mm):
        d = np.sort(days[:, i])
        finite = np.isfinite(d)
        if finite.any():
            ax.step(d[finite], np.arange(1, finite.sum() + 1) / d.size, where="post", label=f"{level:g} mm")
    ax.set_xscale("log")
    ax.set_xlabel(f"calendar days to the clearance ({data.get('duty_text', '')})")
    ax.set_ylabel("fraction of the samples")
    ax.set_ylim(0.0, 1.0)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no sample reaches a level\nwithin the horizon", transform=ax.transAxes, ha="center")
    ax = fig.add_subplot(1, 2, 2)
    stops = data.get("stop_start_share")
    if stops:
        names = list(stops["by_design_point"])
        ax.barh(names, [100.0 * stops["by_design_point"][n] for n in names], color="C1")
        ax.set_xlabel("share of the worn volume from stop-starts, %")
        ax.tick_params(axis="y", labelsize=7)
    else:
        ax.text(0.5, 0.5, "no stops ([duty] stops_per_hour = 0)", transform=ax.transAxes, ha="center")
        ax.set_axis_off()
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def duty_text(scene: Scene, values: dict) -> str:
    """The duty of the report's calendar time, the drawn keys named as drawn."""
    duty = scene.duty
    parts = []
    for name, unit in (("hours_per_day", "h a day"), ("days_per_week", "days a week"), ("stops_per_hour", "stops an h")):
        parts.append(f"{'drawn' if f'duty.{name}' in values else f'{getattr(duty, name):g}'} {unit}")
    return ", ".join(parts)


__all__ = ["DUTY_KEYS", "SHIFTS", "duty_text", "horizon_days", "life_figure", "prediction_stop_share", "sample_days",
           "shift_days", "stop_share_summary"]
