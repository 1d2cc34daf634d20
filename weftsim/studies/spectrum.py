"""Amplitude spectrum of the rapier acceleration (paper Fig. 13, "acceleration spectrum").

Convention (single-sided amplitude spectrum): over a window of length T holding a
whole number of crank revolutions, the signal a(t) is written as

    a(t) = A_0 + sum_{k >= 1} A_k cos(2 pi f_k t + phi_k),    f_k = k / T,

and :func:`amplitude_spectrum` returns f_k (Hz) and A_k (same unit as a, m/s^2 for the
acceleration).  With N uniform samples and X = rfft(a) this is the usual
``A_0 = |X_0| / N`` and ``A_k = 2 |X_k| / N`` (the Nyquist bin, if any, ``|X| / N``): a
pure sine of amplitude A at one of the f_k gives back exactly A at f_k.  Because the
window holds whole revolutions, every harmonic of the crank frequency f_rev = omega /
(2 pi) falls on a bin (k = m x revolutions) and no window function is needed for the
periodic part.

Aliasing.  The solver steps are not evenly spaced and an impact lasts ~0.1 ms, less
than one output sample (0.5 deg = 0.2 ms at 400 rpm), so sampling the signal at points
would fold the impact spikes into every frequency.  Instead the per-step signal is
taken as piecewise linear between steps and averaged over each of N uniform bins (the
exact integral of the interpolant); the FFT of these bin means is the spectrum of the
signal convolved with a box of one bin width.  Its gain sinc(f / f_s) (f_s = N / T) is
divided out, so a sine on a line comes back exact; the box's zeros at multiples of f_s
also suppress what would alias onto the low lines (content near m f_s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from weftsim.post.results import RunResult

DEFAULT_BINS_PER_REVOLUTION = 720  # 0.5 deg, the output grid of the scenes


@dataclass(frozen=True)
class Spectrum:
    """A single-sided amplitude spectrum.

    Attributes
    ----------
    frequency_hz : ndarray
        f_k = k / T, Hz.
    amplitude : ndarray
        A_k (unit of the signal), see the module docstring.
    window_s : tuple of float
        (t0, t1) of the analysed window, s.
    revolutions : int
        Whole crank revolutions in the window (0 when not built from a run).
    """

    frequency_hz: np.ndarray
    amplitude: np.ndarray
    window_s: tuple[float, float]
    revolutions: int = 0

    def peak(self, low_hz: float = 0.0, high_hz: float = math.inf, skip_zero: bool = True) -> tuple[float, float]:
        """(frequency, amplitude) of the largest amplitude with low <= f <= high (f = 0 skipped by default)."""
        f, a = self.frequency_hz, self.amplitude
        keep = (f >= low_hz) & (f <= high_hz)
        if skip_zero:
            keep &= f > 0.0
        if not np.any(keep):
            raise ValueError(f"no spectral line between {low_hz} and {high_hz} Hz")
        i = np.flatnonzero(keep)[np.argmax(a[keep])]
        return float(f[i]), float(a[i])

    def power_fraction(self, low_hz: float, high_hz: float) -> float:
        """Share of the mean square of the signal minus its mean carried by lines in [low, high] Hz.

        Parseval: mean square of the fluctuation = sum_{k >= 1} A_k^2 / 2.
        """
        f, a = self.frequency_hz, self.amplitude
        power = np.where(f > 0.0, 0.5 * a * a, 0.0)
        total = float(power.sum())
        if total == 0.0:
            return 0.0
        return float(power[(f >= low_hz) & (f <= high_hz)].sum() / total)


def bin_means(time: np.ndarray, values: np.ndarray, t0: float, t1: float, bins: int) -> np.ndarray:
    """Mean of the piecewise-linear interpolant of (time, values) over each of ``bins`` equal bins of [t0, t1].

    The bin edges are inserted among the data times (values there by linear
    interpolation); the cumulative trapezoidal integral over the merged times is then
    the exact integral of the interpolant up to each edge.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    if time.ndim != 1 or time.shape != values.shape:
        raise ValueError(f"`time` and `values` must be 1-D of one length, got {time.shape} and {values.shape}")
    if time.size < 2 or np.any(np.diff(time) < 0.0):
        raise ValueError("`time` must hold at least 2 non-decreasing values")
    if not (time[0] <= t0 + 1e-12 * max(1.0, abs(t0)) and t1 <= time[-1] + 1e-12 * max(1.0, abs(t1)) and t0 < t1):
        raise ValueError(f"window [{t0}, {t1}] s must lie inside the data [{time[0]}, {time[-1]}] s")
    edges = np.linspace(t0, t1, bins + 1)
    inside = (time > t0) & (time < t1)
    t = np.concatenate([edges, time[inside]])
    order = np.argsort(t, kind="stable")
    t = t[order]
    v = np.interp(t, time, values)
    area = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    # The edges are in t: their cumulative areas are exact integrals of the interpolant.
    at_edges = area[np.searchsorted(t, edges, side="left")]
    return np.diff(at_edges) / np.diff(edges)


def amplitude_spectrum(time: np.ndarray, values: np.ndarray, t0: float, t1: float,
                       bins: int, revolutions: int = 0) -> Spectrum:
    """Single-sided amplitude spectrum of a signal over [t0, t1] (see the module docstring).

    Parameters
    ----------
    time, values : (M,) ndarray
        Samples of the signal, time non-decreasing (solver steps: any spacing).
    t0, t1 : float
        Window, s; its length T sets the line spacing 1 / T.
    bins : int
        Number of uniform bins (N); the highest line is N / (2 T).
    revolutions : int
        Recorded in the result only.
    """
    if bins < 2:
        raise ValueError(f"`bins` must be >= 2, got {bins}")
    means = bin_means(time, values, t0, t1, bins)
    transform = np.fft.rfft(means)
    frequency = np.fft.rfftfreq(bins, d=(t1 - t0) / bins)
    # Bin means = box filter of one bin width: divide out its gain sinc(k / N) (>= 2/pi up to Nyquist).
    amplitude = np.abs(transform) / bins / np.sinc(np.arange(transform.size) / bins)
    amplitude[1:] *= 2.0
    if bins % 2 == 0:
        amplitude[-1] *= 0.5  # the Nyquist line has no mirror image
    return Spectrum(frequency, amplitude, (float(t0), float(t1)), revolutions)


def acceleration_spectrum(result: RunResult, skip_revolutions: int = 1,
                          bins_per_revolution: int = DEFAULT_BINS_PER_REVOLUTION,
                          channel: str = "rapier_acceleration_m_s2") -> Spectrum:
    """Amplitude spectrum of the rapier acceleration over the whole revolutions after ``skip_revolutions``.

    Parameters
    ----------
    result : weftsim.post.results.RunResult
        Uses the per-step channels (every accepted solver step).
    skip_revolutions : int
        Start-up revolutions left out (1: the start-up impact from the centred journal).
    bins_per_revolution : int
        Uniform bins per revolution; the highest line is bins_per_revolution / 2 x f_rev.
    channel : str
        Any per-step channel; the rapier acceleration by default.

    Raises
    ------
    ValueError
        When the run has no whole revolution after the skipped ones.
    """
    from weftsim.post.analysis import complete_revolutions

    n = complete_revolutions(result)
    count = n - skip_revolutions
    if count < 1:
        raise ValueError(f"the spectrum needs at least one whole revolution after the first {skip_revolutions}; "
                         f"the run has {n} (raise drive.revolutions)")
    period = result.scene.drive.period
    t0, t1 = skip_revolutions * period, n * period
    t = result.steps["time_s"]
    # The run's last step lands on its end time up to round-off: clip the window to the data.
    t1 = min(t1, float(t[-1])) if abs(t1 - t[-1]) < 1e-9 * period else t1
    return amplitude_spectrum(t, result.steps[channel], t0, t1, bins_per_revolution * count, count)
