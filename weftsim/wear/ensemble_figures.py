"""Figures of a wear ensemble (no physics): the CDF of the hours to the limit, the clearance-against-hours
band and the inputs' shares of the spread.  matplotlib is imported only when called."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.post.plots import figure

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
        ax.text(0.02, 0.97, f"{100 * reach:.3g} % reach it within {right:.3g} h (dotted);\n"
                f"{100 * (1 - reach):.3g} % later or never (censored)", transform=ax.transAxes, ha="left", va="top",
                fontsize=9)
    for name, q in data["hours_to_limit"].items():
        if q["hours"] is None:  # among the censored
            continue
        ax.axvline(q["hours"], color="C1", lw=1)
        if q["low"] is not None and q["high"] is not None and np.isfinite(q["low"]) and np.isfinite(q["high"]):
            ax.axvspan(q["low"], q["high"], color="C1", alpha=0.2)
        # The curve crosses the line at p: right of it the curve is above p, left of it below, so a label
        # right of the line and below p (or left of it and above p) sits on empty ground.
        p = float(name[1:]) / 100.0
        low_side = p < 0.5
        ax.annotate(f"{name} {q['hours']:.4g} h", (q["hours"], p), xytext=(4 if low_side else -4, -6 if low_side else 6),
                    textcoords="offset points", ha="left" if low_side else "right",
                    va="top" if low_side else "bottom", fontsize=8,
                    bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.0})
    if x.size or horizon:
        _log_hours_axis(ax)
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel(f"hours to an effective clearance of {data['limit_clearance_mm']:g} mm (the limit) [h]")
    ax.set_ylabel("probability of reaching it earlier")
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return fig


def _log_hours_axis(ax) -> None:
    """A log axis of hours with labels that do not collide: majors at each decade over more than 2.5 decades, at
    1, 2 and 5 of each decade over fewer, finer within one; written plainly (2000, 5e+04), no minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    ax.set_xscale("log")
    low, high = ax.get_xlim()
    decades = np.log10(high / low) if low > 0.0 and high > low else 1.0
    subs = (1.0,) if decades > 2.5 else (1.0, 2.0, 5.0) if decades > 0.7 else (1.0, 1.5, 2.0, 3.0, 5.0, 7.0)
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=subs, numticks=12))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


def band_figure(band: dict, title: str = "", limit_mm: float | None = None) -> Figure:
    """Effective clearance against hours: median and the 10-90 % band; with censored samples (a quantile
    beyond the horizon is inf) a second panel gives the fraction of samples reaching each clearance."""
    censored = "fraction_reaching" in band and np.any(np.asarray(band["fraction_reaching"]) < 1.0)
    fig = figure(figsize=(10 if censored else 7, 4.5))
    ax = fig.add_subplot(1, 2 if censored else 1, 1)
    c = band["clearance_e_mm"]
    p10, p50, p90 = (np.asarray(band[f"hours_p{p}"], dtype=float) for p in (10, 50, 90))
    both = np.isfinite(p10) & np.isfinite(p90)
    ax.fill_betweenx(np.where(both, c, np.nan), np.where(both, p10, np.nan), np.where(both, p90, np.nan),
                     color="C0", alpha=0.25, label="10-90 %")
    for q, style, name in ((p10, ":", "10 %"), (p50, "-", "median"), (p90, "--", "90 %")):
        if np.any(np.isfinite(q)):
            ax.plot(np.where(np.isfinite(q), q, np.nan), c, color="C0", ls=style, label=name)
    if limit_mm is not None:
        ax.axhline(limit_mm, color="C3", ls="--", lw=1, label=f"limit {limit_mm:g} mm")
    ax.set_xlabel("operating hours [h]" + (" (where the quantile is reached within the horizon)" if censored else ""))
    ax.set_ylabel("effective clearance at E [mm]")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="lower right")
    ax.grid(True, alpha=0.3)
    if censored:
        ax2 = fig.add_subplot(1, 2, 2, sharey=ax)
        ax2.plot(100.0 * np.asarray(band["fraction_reaching"]), c, color="C3")
        ax2.set_xlim(0, 100)
        ax2.set_xlabel("samples reaching the clearance within the horizon (%)")
        ax2.grid(True, alpha=0.3)
    fig.tight_layout()
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
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return fig
