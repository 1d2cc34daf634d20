"""Peaks and statistics are taken from every solver step and weighted by time."""

import math

import numpy as np
import pytest

from weftsim.post import analysis
from weftsim.input.params import Scene
from weftsim.post.results import CHANNELS, RunResult


def synthetic(time, **channels):
    data = {name: np.zeros_like(time) for name in CHANNELS}
    data["time_s"] = time
    data.update(channels)
    scene = Scene()
    data["crank_angle_deg"] = np.degrees(scene.drive.speed * time)
    return RunResult(scene=scene, engine="reference", status="success", message="", samples=data, steps=data)


def test_time_weighted_statistics_ignore_step_density():
    # A sine sampled densely on its first half and sparsely on its second: an unweighted
    # mean would be biased towards the dense half; the trapezoidal mean is ~0.
    t = np.concatenate([np.linspace(0, 0.5, 5001), np.linspace(0.5, 1, 51)[1:]])
    stats = analysis.channel_statistics(t, np.sin(2 * math.pi * t))
    # Trapezoid rule with 51 points per half period: error ~ (dt)^2 ~ 1e-3 of the amplitude.
    assert abs(stats["mean"]) < 2e-3
    assert stats["rms"] == pytest.approx(1 / math.sqrt(2), rel=1e-3)
    # |sin| stays below sin(0.99 pi/2) for 99% of the time; grid error ~1e-3 as above.
    assert stats["p99_abs"] == pytest.approx(math.cos(math.pi / 2 * 0.01), abs=2e-3)


def test_peaks_per_revolution_catch_a_short_spike_between_samples():
    scene = Scene()
    period = scene.drive.period
    t = np.sort(np.concatenate([np.linspace(0, 2 * period, 721), 1.5 * period + np.linspace(-1e-4, 1e-4, 41)]))
    force = np.where(np.abs(t - 1.5 * period) < 5e-5, 1e4, 0.0)
    result = synthetic(t, contact_force_N=force)
    assert analysis.complete_revolutions(result) == 2
    assert analysis.peaks(result, 0)["contact_force_N"]["max"] == 0.0
    assert analysis.peaks(result, 1)["contact_force_N"]["max"] == 1e4
    summary = analysis.summary(result)
    assert summary["peaks"]["revolution"] == 2
    assert [r["revolution"] for r in summary["revolutions"]] == [1, 2]


def test_energy_balance_residual():
    t = np.linspace(0, 0.3, 301)
    ke = 1 + t
    work = 2 * t
    result = synthetic(t, kinetic_energy_J=ke, driving_work_J=work, dissipated_energy_J=t)
    balance = analysis.energy_balance(result)
    assert balance["residual_J"] == pytest.approx(0.0, abs=1e-12)
