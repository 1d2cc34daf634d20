"""Figures of a wear ensemble (no physics): the CDF of the hours to the limit, the clearance-against-hours
band and the inputs' shares of the spread.  matplotlib is imported only when called."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.plots import figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def cdf_figure(hours: np.ndarray, data: dict, title: str = "") -> Figure:
    """Empirical distribution function of the hours to the limit, with p10/p50/p90 and their intervals.

    Censored samples (``inf``: not reaching the limit within the horizon) count in the denominator: the
    curve ends at the fraction that reaches the limit, drawn as a dashed line with the horizon."""
    fig = figure(figsize=(7, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    x = np.sort(hours[np.isfinite(hours)])
    n = hours.size
    horizon = data.get("horizon_hours")
    if x.size:
        ax.step(x, np.arange(1, x.size + 1) / n, where="post", color="C0")
    reach = x.size / n
    if x.size < n:
        right = horizon if horizon else (x.max() if x.size else 1.0)
        ax.axhline(reach, color="C0", ls="--", lw=1)
        ax.axvline(right, color="0.4", ls=":", lw=1)
        ax.text(right, reach, f"{100 * reach:.3g} % reach it within {right:.3g} h;\n{100 * (1 - reach):.3g} % "
                "later or never ", ha="right", va="bottom", fontsize=8)
    for name, q in data["hours_to_limit"].items():
        if q["hours"] is None:  # among the censored
            continue
        ax.axvline(q["hours"], color="C1", lw=1)
        if q["low"] is not None and q["high"] is not None and np.isfinite(q["low"]) and np.isfinite(q["high"]):
            ax.axvspan(q["low"], q["high"], color="C1", alpha=0.2)
        ax.text(q["hours"], 0.02, f" {name} {q['hours']:.4g} h", rotation=90, va="bottom", fontsize=8)
    if x.size or horizon:
        ax.set_xscale("log")
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel(f"hours to an effective clearance of {data['limit_clearance_mm']:g} mm")
    ax.set_ylabel("probability of reaching it earlier")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def band_figure(band: dict, title: str = "") -> Figure:
    """Effective clearance against hours: median and the 10-90 % band."""
    fig = figure(figsize=(7, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    c = band["clearance_mm"]
    p10, p50, p90 = (np.asarray(band[f"hours_p{p}"], dtype=float) for p in (10, 50, 90))
    right = np.isfinite(p90)  # beyond: p90 among the censored (does not reach that clearance in the horizon)
    ax.fill_betweenx(c[right], p10[right], p90[right], color="C0", alpha=0.25, label="10-90 %")
    if not np.all(right):
        ok = np.isfinite(p10) & ~right
        top = np.nanmax(np.where(np.isfinite(p90), p90, np.where(np.isfinite(p10), p10, np.nan))) \
            if np.any(np.isfinite(p10)) else 1.0
        ax.fill_betweenx(c[ok], p10[ok], np.full(ok.sum(), top), color="C0", alpha=0.1,
                         label="10 % - (90 % later or never)")
    ax.plot(np.where(np.isfinite(p50), p50, np.nan), c, color="C0", label="median")
    ax.set_xlabel("operating hours")
    ax.set_ylabel("effective clearance at E (mm)")
    ax.set_title(title)
    ax.legend(loc="lower right")
    ax.grid(True, alpha=0.3)
    return fig


def shares_figure(data: dict, title: str = "") -> Figure:
    """Each input's share of the spread of log hours (squared rank correlations, normalised)."""
    fig = figure(figsize=(9, 1.6 + 0.5 * len(data["shares"])))
    ax = fig.add_subplot(1, 1, 1)
    names = list(data["shares"])
    shares = [data["shares"][n]["share"] for n in names]
    signs = [data["shares"][n]["rank_correlation"] for n in names]
    ax.barh(names, shares, color=["C3" if s < 0 else "C0" for s in signs])
    for i, (s, r) in enumerate(zip(shares, signs)):
        ax.text(s, i, f" {100 * s:.0f} % (rho {r:+.2f})", va="center", fontsize=8)
    ax.set_xlim(0, 1.15)
    ax.set_xlabel("share of the spread of log(hours to the limit); red: more of it, fewer hours")
    ax.set_title(title)
    fig.tight_layout()
    return fig
