"""Peaks, statistics and energy balance of a :class:`weftsim.post.results.RunResult`.

Everything here reads the per-step channels (``result.steps``): the solver steps
resolve impacts that fall between output samples.  Steps are not evenly spaced
in time, so means, RMS and percentiles are time-weighted (trapezoidal weights).
"""

from __future__ import annotations

import math

import numpy as np

from weftsim.post.results import (
    PEAK_CHANNELS, PEAK_CHANNELS_F, PEAK_CHANNELS_LUBRICATION, PEAK_CHANNELS_LUBRICATION_F, PEAK_CHANNELS_TAPE,
    RunResult,
)  # fmt: skip


def peak_channels(result: RunResult) -> tuple[str, ...]:
    """The channels summarised by peaks and statistics: :data:`PEAK_CHANNELS`, joint F's when it has a
    clearance, and the film ratio and film, asperity and torque channels of each lubricated joint (the
    film ratio's ``min`` is its summary: the thinnest film of the run), and each loose joint's load
    (``joint_force_N``, ``joint_force_f_N``: film + asperities + dry law)."""
    names = PEAK_CHANNELS + (PEAK_CHANNELS_F if result.has_joint_f else ())
    if "film_ratio" in result.steps:
        names += ("film_ratio",) + PEAK_CHANNELS_LUBRICATION
    if "film_ratio_f" in result.steps:
        names += ("film_ratio_f",) + PEAK_CHANNELS_LUBRICATION_F
    names += tuple(name for name in ("joint_force_N", "joint_force_f_N") if name in result.steps)
    if "head_acceleration_m_s2" in result.steps:  # the flexible rapier tape (docs/rapier-tape.md)
        names += PEAK_CHANNELS_TAPE
    return names


def revolution_index(time: np.ndarray, period: float) -> np.ndarray:
    """0-based crank revolution of each time; a time exactly at k*period belongs to revolution k-1's end."""
    k = np.floor(np.asarray(time) / period + 1e-12).astype(int)
    return k


def _window(result: RunResult, t0: float, t1: float) -> dict[str, np.ndarray]:
    """Per-step channels with t0 <= t <= t1 (both ends kept so a revolution's boundary samples count)."""
    t = result.steps["time_s"]
    keep = (t >= t0 - 1e-12) & (t <= t1 + 1e-12)
    return {name: values[keep] for name, values in result.steps.items()}


def time_weights(time: np.ndarray) -> np.ndarray:
    """Trapezoidal weights w_i with sum(w) = t[-1] - t[0] (0 for a single sample)."""
    time = np.asarray(time, dtype=float)
    if time.size < 2:
        return np.ones_like(time)
    dt = np.diff(time)
    w = np.zeros_like(time)
    w[:-1] += 0.5 * dt
    w[1:] += 0.5 * dt
    return w


def weighted_percentile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """Percentile q (0-100) of values carrying the given weights (piecewise-linear CDF)."""
    order = np.argsort(values)
    v, w = np.asarray(values)[order], np.asarray(weights)[order]
    cdf = np.cumsum(w) - 0.5 * w
    total = w.sum()
    if total <= 0:
        return float(np.percentile(values, q))
    return float(np.interp(q / 100.0 * total, cdf, v))


def channel_statistics(time: np.ndarray, values: np.ndarray) -> dict[str, float]:
    """Time-weighted mean, RMS, 99th percentile (of the value and of its magnitude), min and max."""
    w = time_weights(time)
    total = w.sum()
    mean = float(np.dot(w, values) / total)
    rms = float(math.sqrt(np.dot(w, values * values) / total))
    return {
        "mean": mean,
        "rms": rms,
        "p99": weighted_percentile(values, w, 99.0),
        "p99_abs": weighted_percentile(np.abs(values), w, 99.0),
        "min": float(values.min()),
        "max": float(values.max()),
    }


def complete_revolutions(result: RunResult) -> int:
    """Number of whole crank revolutions the run covers (a failed run may cover fewer than asked)."""
    t = result.steps["time_s"]
    if t.size == 0:
        return 0
    return int(math.floor(t[-1] / result.scene.drive.period + 1e-9))


def peaks(result: RunResult, revolution: int) -> dict[str, dict[str, float]]:
    """Min and max of each peak channel over one (0-based) revolution."""
    period = result.scene.drive.period
    window = _window(result, revolution * period, (revolution + 1) * period)
    if window["time_s"].size == 0:
        raise ValueError(f"revolution {revolution + 1} has no solver steps")
    return {name: {"min": float(window[name].min()), "max": float(window[name].max())}
            for name in peak_channels(result)}


def statistics(result: RunResult, skip_revolutions: int = 1) -> dict[str, dict[str, float]] | None:
    """Statistics of each peak channel over all whole revolutions after the first ``skip_revolutions``."""
    n = complete_revolutions(result)
    if n <= skip_revolutions:
        return None
    period = result.scene.drive.period
    window = _window(result, skip_revolutions * period, n * period)
    return {name: channel_statistics(window["time_s"], window[name]) for name in peak_channels(result)}


def energy_balance(result: RunResult) -> dict[str, float]:
    """Residual of W_drive = dKE + dPE + E_contact + E_dissipated at the last step, J.

    Returns the terms, the residual and the residual relative to the largest
    kinetic energy of the run (the natural scale of the balance).
    """
    s = result.steps
    d_kinetic = s["kinetic_energy_J"][-1] - s["kinetic_energy_J"][0]
    d_potential = s["potential_energy_J"][-1] - s["potential_energy_J"][0]
    contact = s["contact_energy_J"][-1] - s["contact_energy_J"][0]
    dissipated = s["dissipated_energy_J"][-1] - s["dissipated_energy_J"][0]
    work = s["driving_work_J"][-1] - s["driving_work_J"][0]
    residual = work - (d_kinetic + d_potential + contact + dissipated)
    scale = float(np.max(np.abs(s["kinetic_energy_J"]))) or 1.0
    return {
        "driving_work_J": float(work),
        "kinetic_energy_change_J": float(d_kinetic),
        "potential_energy_change_J": float(d_potential),
        "contact_energy_change_J": float(contact),
        "dissipated_energy_J": float(dissipated),
        "residual_J": float(residual),
        "relative_residual": float(residual / scale),
    }


def summary(result: RunResult) -> dict:
    """The content of ``summary.json`` (see the README's output reference)."""
    from weftsim.post.provenance import commit, versions
    from weftsim.input.scene import to_file_keys
    from weftsim.model.exchange import exchange_summary

    n = complete_revolutions(result)
    per_revolution = []
    for k in range(n):
        per_revolution.append({"revolution": k + 1, **peaks(result, k)})
    return {
        "scene": to_file_keys(result.scene),
        "engine": result.engine,
        # The model and method that ran, and why (the engine's automatic selection or the scene's keys).
        "path": dict(result.path) or None,
        "status": result.status,
        # False for a failed run: what it holds ends where the run stopped (simulated_time_s).
        "complete": result.ok,
        "simulated_time_s": float(result.steps["time_s"][-1]) if result.steps["time_s"].size else 0.0,
        "message": result.message,
        "complete_revolutions": n,
        "peaks": per_revolution[-1] if per_revolution else None,
        "revolutions": per_revolution,
        "statistics": statistics(result),
        "first_contact_crank_angle_deg": result.first_contact_angle_deg,
        "energy_balance": energy_balance(result) if result.steps["time_s"].size else None,
        # The weft exchange with the taker head (weftsim.model.exchange; None without an [exchange] that is on).
        "exchange": exchange_summary(result.scene, result.steps, result.solver_stats.get("exchange_taker")),
        # Counts of a broken contact history and the law-range warnings (weftsim.checks.plausibility; not for
        # the ideal mechanism) and the design checks with their verdicts (weftsim.checks.design_checks).
        "plausibility": dict(result.plausibility) or None,
        "solver": dict(result.solver_stats),
        "wall_time_s": result.wall_time_s,
        # What computed it: Python and package versions, and the git commit when run from a checkout.
        "versions": versions(),
        "commit": commit(),
    }
