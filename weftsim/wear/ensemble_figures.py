"""Figures of a wear ensemble (no physics): the CDF of the hours to the limit, the clearance-against-hours
band and the inputs' shares of the spread.  matplotlib is imported only when called."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.post.plots import figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def cdf_figure(hours: np.ndarray, data: dict, title: str = "") -> Figure:
    """Empirical distribution function of the hours to the limit, with p10/p50/p90 and their intervals."""
    fig = figure(figsize=(7, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    x = np.sort(hours)
    ax.step(x, np.arange(1, x.size + 1) / x.size, where="post", color="C0")
    for name, q in data["hours_to_limit"].items():
        ax.axvline(q["hours"], color="C1", lw=1)
        if np.isfinite(q["low"]) and np.isfinite(q["high"]):
            ax.axvspan(q["low"], q["high"], color="C1", alpha=0.2)
        ax.text(q["hours"], 0.02, f" {name} {q['hours']:.4g} h", rotation=90, va="bottom", fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel(f"hours to an effective clearance of {data['limit_clearance_mm']:g} mm")
    ax.set_ylabel("probability of reaching it earlier")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def band_figure(band: dict, title: str = "") -> Figure:
    """Effective clearance against hours: median and the 10-90 % band."""
    fig = figure(figsize=(7, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    c = band["clearance_e_mm"]
    ax.fill_betweenx(c, band["hours_p10"], band["hours_p90"], color="C0", alpha=0.25, label="10-90 %")
    ax.plot(band["hours_p50"], c, color="C0", label="median")
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
