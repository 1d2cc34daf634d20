"""Figures of the studies (no physics here; matplotlib imported only when called).

Axes are labelled in the paper's units: mm, deg, m/s², N·m, N, Hz.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from weftsim.post.plots import pyplot, channel_panels  # noqa: F401 - channel_panels re-exported for the studies

if TYPE_CHECKING:
    from collections.abc import Sequence

    from matplotlib.figure import Figure


def trend_panels(x: Sequence[float], x_label: str, panels: list[tuple], title: str,
                 x_ticks: Sequence[float] | None = None) -> Figure:
    """Rows of reproducible quantities against a study parameter.

    Parameters
    ----------
    x : sequence of float
    panels : list of (y_label, [(label, values), ...])
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8))
    for ax, (y_label, lines) in zip(np.atleast_1d(axes), panels):
        for label, values in lines:
            y = [np.nan if v is None else v for v in values]
            ax.plot(x, y, "o-", label=label)
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        if x_ticks is not None:
            ax.set_xticks(x_ticks)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def spectrum_panels(spectra: list[tuple], title: str, low_band_hz: float = 100.0) -> Figure:
    """Amplitude spectra: 0..low_band_hz on a linear scale, the whole band on a log scale.

    Parameters
    ----------
    spectra : list of (label, Spectrum, style)
    """
    plt = pyplot()
    fig, (near, full) = plt.subplots(2, 1, figsize=(10, 8))
    for label, spectrum, style in spectra:
        f, a = spectrum.frequency_hz, spectrum.amplitude
        keep = f <= low_band_hz
        near.plot(f[keep], a[keep], "-", marker=".", ms=3, lw=0.8, label=label, **style)
        full.semilogy(f[1:], a[1:], lw=0.6, label=label, **style)
    near.axvspan(0.0, 10.0, color="0.85", zorder=0, label="0-10 Hz (paper: main content)")
    near.set_xlim(0, low_band_hz)
    near.set_xlabel("frequency [Hz]")
    near.set_ylabel("rapier acceleration amplitude [m/s²]")
    full.set_xlabel("frequency [Hz]")
    full.set_ylabel("rapier acceleration amplitude [m/s²]")
    full.set_xlim(0, max(s.frequency_hz[-1] for _, s, _ in spectra))
    for ax in (near, full):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def contact_law_panels(curve: dict, revolution: dict, law_lines: list[tuple], title: str) -> Figure:
    """Paper Fig. 7-9: K against penetration, K along a revolution, D against penetration.

    Parameters
    ----------
    curve : dict
        ``penetration_mm``, ``stiffness`` (the law), ``stiffness_constant`` (K_LN, for reference).
    revolution : dict
        Steps in contact: ``crank_angle_deg``, ``penetration_mm``, ``stiffness``, ``damping``,
        ``impact_velocity_m_s``.
    law_lines : list of (label, penetration_mm, damping)
        D(delta) of the law at fixed impact velocities.
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axes[0]
    ax.plot(curve["penetration_mm"], curve["stiffness"], label="variable_kd K(δ) (Bai-Zhao)")
    ax.axhline(curve["stiffness_constant"], color="0.4", ls="--", lw=0.8, label="lankarani_nikravesh K (constant)")
    ax.axvline(0.005, color="0.6", ls=":", lw=0.8, label="δ = 0.005 mm (paper: flattening)")
    ax.set_xlabel("penetration δ [mm]")
    ax.set_ylabel("contact stiffness K [N/m^1.5]")
    ax.set_title("(a) stiffness against penetration (Fig. 7)", fontsize=10)
    ax = axes[1]
    if revolution["crank_angle_deg"].size:
        ax.plot(revolution["crank_angle_deg"], revolution["stiffness"], ".", ms=1.5)
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("contact stiffness K [N/m^1.5]")
    ax.set_title("(b) stiffness along a revolution, steps in contact (Fig. 8)", fontsize=10)
    ax = axes[2]
    if revolution["penetration_mm"].size:
        points = ax.scatter(revolution["penetration_mm"], revolution["damping"], s=2,
                            c=np.log10(revolution["impact_velocity_m_s"]), cmap="viridis")
        fig.colorbar(points, ax=ax, label="log10 impact velocity [m/s]")
    for (label, penetration, damping), ls in zip(law_lines, ("--", ":", "-.")):
        ax.plot(penetration, damping, color="k", ls=ls, lw=0.8, label=label)
    ax.set_xlabel("penetration δ [mm]")
    ax.set_ylabel("contact damping D [N·s/m]")
    ax.set_title("(c) damping against penetration (Fig. 9)", fontsize=10)
    for a in axes:
        a.grid(alpha=0.3)
    for a in (axes[0], axes[2]):
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize=7, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def deviation_panel(bin_centres: np.ndarray, deviations: list[tuple], markers: list[tuple], title: str) -> Figure:
    """RMS deviation of the rapier acceleration from the ideal one per crank-angle bin.

    Parameters
    ----------
    deviations : list of (label, values, style)
    markers : list of (label, angles_deg, style)
        Vertical lines, e.g. the ideal acceleration extremes and velocity zeros.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 4.2))
    width = bin_centres[1] - bin_centres[0] if len(bin_centres) > 1 else 10.0
    for label, values, style in deviations:
        ax.step(bin_centres, values, where="mid", label=label, **style)
    for label, angles, style in markers:
        for k, angle in enumerate(angles):
            ax.axvline(angle, label=label if k == 0 else None, **style)
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 30))
    if any(np.any(np.asarray(values) > 0) for _, values, _ in deviations):
        ax.set_yscale("log")
    ax.set_xlabel(f"crank angle [deg] ({width:g} deg bins)")
    ax.set_ylabel("RMS of a − a_ideal [m/s²]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best", ncol=2)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig
