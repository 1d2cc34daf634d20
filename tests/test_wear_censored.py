"""Wear predictions that never reach a clearance limit (docs/wear.md section 9, "Lubricated"): a full film
wears nothing and is reported as "never" (exit 0), an ensemble's quantiles among such samples are censored
("> H h", null with a flag in JSON, never Infinity), the fraction reaching the limit is given, and the design
interpolation has a rule across a design point that never wears; the oil's viscosity from its temperature."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from weftsim.errors import WearError
from weftsim.input.scene import apply_overrides, load_scene
from weftsim.wear import ensemble
from weftsim.wear.censored import censored_quantile, fraction_interval
from weftsim.wear.ensemble_design import _hat, interpolate
from weftsim.wear.jobs import hours_at, run_job
from weftsim.wear.uncertain import OIL_DENSITY_15C, OIL_DENSITY_PER_K, parse_uncertain, walther_viscosity

ROOT = Path(__file__).resolve().parents[1]
LOOM = ROOT / "models" / "loom.toml"


def test_censored_quantile_is_exact_below_the_censored_and_inf_among_them():
    """70 of 100 samples reach the limit: p10 and p50 are the plain quantiles of all 100 (the censored sort
    last, whatever their true hours), p90 falls among the censored."""
    rng = np.random.default_rng(4)
    finite = np.sort(rng.lognormal(3.0, 0.5, 70))
    hours = np.concatenate([finite, np.full(30, math.inf)])
    stand_in = np.concatenate([finite, np.full(30, 1e9)])  # any values above the finite ones
    for p in (0.1, 0.5):
        est, low, high = censored_quantile(hours, p)
        assert est == pytest.approx(np.quantile(stand_in, p), rel=1e-14)
        assert math.isfinite(low) and math.isfinite(high)
    est, low, high = censored_quantile(hours, 0.9)
    assert est == math.inf and high == math.inf
    # the 69th-70th order statistics straddle the censoring: the interpolating estimate is censored too
    assert censored_quantile(hours, 69.5 / 99)[0] == math.inf


def test_fraction_interval_is_clopper_pearson():
    """0 of 10: the upper bound solves (1 - p)^10 = 0.05; 10 of 10 mirrors it; 5 of 10 is symmetric."""
    assert fraction_interval(0, 10)[2] == pytest.approx(1.0 - 0.05 ** 0.1, rel=1e-10)
    assert fraction_interval(10, 10)[1] == pytest.approx(0.05 ** 0.1, rel=1e-10)
    frac, low, high = fraction_interval(5, 10)
    assert frac == 0.5 and low == pytest.approx(1.0 - high, rel=1e-10)


def test_inverse_hours_are_interpolated_across_a_design_point_that_never_wears():
    """One key, three design points of 100 h, 400 h and never: the inverse hours are linear between the
    points (closed forms below), a sample at the never point never reaches the level; a level every point
    reaches keeps the quadratic log-hours rule."""
    key = parse_uncertain("drive.speed_rpm=uniform(500,700)")
    nodes = np.array([[1.0], [2.0], [3.0]])
    node_hours = np.array([[100.0, 10.0], [400.0, 20.0], [math.inf, 40.0]])  # (nodes, levels)
    x = np.array([1.0, 1.5, 2.5, 3.0, 3.5])
    out = interpolate(node_hours, nodes, [key], {key.key: x}, x.size)
    expected = [100.0, 1.0 / (0.5 / 100.0 + 0.5 / 400.0), 1.0 / (0.5 / 400.0), math.inf, math.inf]
    assert out[:, 0] == pytest.approx(expected, rel=1e-14)
    # level 2: log-hours, quadratic through (1, log 10), (2, log 20), (3, log 40): exactly 10 * 2^(x-1)
    assert out[:4, 1] == pytest.approx(10.0 * 2.0 ** (x[:4] - 1.0), rel=1e-12)
    w = _hat(np.array([1.0, 2.0, 3.0]), x)
    assert np.all(w >= 0.0) and w.sum(axis=1) == pytest.approx(1.0, rel=1e-15)


def test_walther_reproduces_its_two_points():
    """ASTM D341 through (40 C, nu40) and (100 C, nu100): the kinematic viscosity there is exact."""
    t = np.array([40.0, 100.0])
    density = OIL_DENSITY_15C - OIL_DENSITY_PER_K * (t - 15.0)
    assert walther_viscosity(220.0, 19.0, t) / density == pytest.approx([220.0, 19.0], rel=1e-12)
    u = parse_uncertain("joint_e.lubrication.viscosity_mpa_s=walther(220,19,45,85)")
    v = u.ppf(np.array([1e-9, 0.5, 1 - 1e-9]))
    assert np.all(np.diff(v) > 0.0)  # rises with the probability (the cold end at u = 1)
    assert v[1] == pytest.approx(walther_viscosity(220.0, 19.0, np.array([65.0]))[0], rel=1e-12)
    for bad in ("drive.speed_rpm=walther(220,19,45,85)", "joint_e.lubrication.viscosity_mpa_s=walther(19,220,45,85)",
                "joint_e.lubrication.viscosity_mpa_s=walther(220,19,85,45)"):
        with pytest.raises(WearError):
            parse_uncertain(bad)


@pytest.fixture(scope="module")
def oiled_loom():
    return apply_overrides(load_scene(LOOM), {"joint_e.lubrication.viscosity_mpa_s": 80.0}, "test")


def test_a_full_film_job_is_censored_never(oiled_loom, tmp_path):
    """At 80 mPa s the loom's film ratio stays above 4 (8.85): the asperities carry nothing, Archard's law wears
    nothing, and the job is censored with the reason instead of failing."""
    result = run_job(oiled_loom, 0.1e-3, str(tmp_path / "j"))
    assert result["error"] is None and result["censored"]
    assert "asperities carry no load" in result["never"] and "film ratio min" in result["never"]
    assert np.all(hours_at(result, np.array([0.05e-3, 0.1e-3])) == math.inf)
    assert result["clearance_m"][-1] == oiled_loom.joint.clearance  # nothing worn


def test_cli_single_run_says_never_and_exits_0(tmp_path):
    out = tmp_path / "w"
    proc = subprocess.run([sys.executable, "-m", "weftsim.cli", "wear", str(LOOM), "--set",
                           "joint_e.lubrication.viscosity_mpa_s=80", "--hours", "20000", "--limit-clearance-mm", "0.1",
                           "--no-plot", "-o", str(out)], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "does not reach 0.1 mm: the asperities carry no load (film ratio min" in proc.stdout
    text = (out / "wear.json").read_text()
    assert "Infinity" not in text and "NaN" not in text
    data = json.loads(text)
    assert data["hours_to_limit"] is None and data["limit_censored"] is True and data["never"]


def _fake(hours, clearance, censored=False, never=None):
    return {"hours": hours, "clearance_m": clearance, "bearing_share": 0.5, "error": None, "censored": censored,
            "never": never, "horizon_h": 1e6, "updates": len(hours), "wall_s": 0.0}


def test_ensemble_with_never_design_points_writes_censored_quantiles(oiled_loom, tmp_path, monkeypatch):
    """Viscosity designed on three points: the thinnest oil reaches 0.1 mm in 2000 h at the nominal k, the
    other two never wear.  Every sample's hours follow the inverse-hours rule by hand (k rescaling, the
    horizon of 1e5 h); p90 is censored;
    ensemble.json holds null with a flag (no Infinity), the CDF figure is drawn."""
    c0 = oiled_loom.joint.clearance
    curves = {"node_0": _fake([0.0, 1000.0, 2000.0], [c0, 0.06e-3, 0.1e-3]),
              "node_1": _fake([0.0, 1e6], [c0, c0], True, "the asperities carry no load (film ratio min 5)"),
              "node_2": _fake([0.0, 1e6], [c0, c0], True, "the asperities carry no load (film ratio min 9)")}
    monkeypatch.setattr(ensemble, "_run_jobs", lambda jobs, *a, **k: {n: curves[n] for n, _ in jobs})
    data = ensemble.wear_ensemble(oiled_loom, {"joint_e.lubrication.viscosity_mpa_s": "uniform(20,80)",
                                               "joint_e.wear.wear_coefficient": "lognormal(1e-7,0.5)"},
                                  400, 0.1e-3, tmp_path / "e", chaos_runs=1, horizon=1e5)
    text = Path(data["files"]["summary"]).read_text()
    assert "Infinity" not in text and "NaN" not in text
    saved = json.loads(text)
    reach = saved["reaching_limit"]
    rows = np.genfromtxt(data["files"]["samples"], delimiter=",", names=True, deletechars="")
    # The rule by hand: design viscosities v0, v1 at the 5 and 50 % points; a sample's inverse hours are
    # (1 - t) / 2000 h for t = (v - v0) / (v1 - v0) clamped to [0, 1], 0 beyond v1; times k / k0.
    v0, v1 = 20.0 + 60.0 * 0.05, 50.0
    t = np.clip((rows["joint_e.lubrication.viscosity_mpa_s"] - v0) / (v1 - v0), 0.0, 1.0)
    with np.errstate(divide="ignore"):
        expected = 2000.0 / (1.0 - t) * 1e-7 / rows["joint_e.wear.wear_coefficient"]
    expected = np.where(expected <= 1e5, expected, math.inf)
    assert np.isfinite(rows["hours_to_limit_e"]).tolist() == np.isfinite(expected).tolist()
    ok = np.isfinite(expected)
    # the CSV holds 10 significant digits of v and k; 1 / (1 - t) amplifies them up to ~50x near v1
    assert rows["hours_to_limit_e"][ok] == pytest.approx(expected[ok], rel=1e-7)
    assert reach["fraction"] == pytest.approx(np.mean(ok), rel=1e-12) and 0.3 < reach["fraction"] < 0.5
    assert reach["low"] < reach["fraction"] < reach["high"]
    assert saved["hours_to_limit"]["p90"] == {**saved["hours_to_limit"]["p90"], "hours": None, "censored": True,
                                              "beyond_hours": 1e5}
    assert saved["hours_to_limit"]["p10"]["censored"] is False and saved["hours_to_limit"]["p10"]["hours"] > 2000.0
    assert set(saved["never"]) == {"node_1", "node_2"}
    assert Path(data["files"]["cdf_figure"]).stat().st_size > 0
    assert np.mean(rows["reaches_limit_e"]) == pytest.approx(reach["fraction"], rel=1e-12)


def test_ensemble_where_nothing_wears_says_so(oiled_loom, tmp_path, monkeypatch):
    """Every design point on a full film: no sample reaches the limit, every quantile is censored, the
    fraction is 0 with its one-sided interval, and the figures are still drawn."""
    c0 = oiled_loom.joint.clearance
    never = _fake([0.0, 1e6], [c0, c0], True, "the asperities carry no load (film ratio min 9)")
    monkeypatch.setattr(ensemble, "_run_jobs", lambda jobs, *a, **k: {n: never for n, _ in jobs})
    data = ensemble.wear_ensemble(oiled_loom, {"joint_e.lubrication.viscosity_mpa_s": "uniform(60,100)"},
                                  100, 0.1e-3, tmp_path / "e", chaos_runs=1, levels=(0.05e-3,))
    saved = json.loads(Path(data["files"]["summary"]).read_text())
    assert saved["reaching_limit"]["fraction"] == 0.0 and saved["reaching_limit"]["low"] == 0.0
    assert saved["reaching_limit"]["high"] == pytest.approx(1.0 - 0.05 ** (1 / 100), rel=1e-10)
    assert all(q["censored"] and q["hours"] is None for q in saved["hours_to_limit"].values())
    assert saved["hours_by_clearance_mm"]["0.05"]["reaching"]["fraction"] == 0.0
    assert all(Path(data["files"][k]).stat().st_size > 0 for k in ("cdf_figure", "band_figure", "shares_figure"))
