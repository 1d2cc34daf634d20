"""The reusable clearance joint on another mechanism: scripts/example_slider_crank.py."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "example_slider_crank.py"


@pytest.fixture(scope="module")
def example():
    spec = importlib.util.spec_from_file_location("example_slider_crank", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def loaded_run(example):
    # 0.1 s at 1e-5 s: the contact mode (~4 kHz) is resolved with omega h ~ 0.25, enough for
    # the quasi-static checks below; the script's default is finer.
    return example.run(end_time=0.1, step=1e-5)


def test_journal_rests_on_the_bearing_under_a_steady_load(example, loaded_run):
    result, clearance = loaded_run
    c = clearance.joint.clearance
    penetration = np.linalg.norm(result["eccentricity"], axis=1) - c
    assert np.all(penetration > 0.0)  # continuous contact after the start-up impacts
    assert penetration.max() < 0.05 * c  # |e| close to c: ~2 um against 100 um
    closed = example.statics(result, clearance.law)
    # Slider equilibrium along X: Newton's law, exact up to Newton tolerance (measured 7e-9).
    np.testing.assert_allclose(result["normal_force"], closed["normal_force"], rtol=1e-6)
    # Quasi-static penetration F_el(delta) = F_N: the law's damping term xi delta_dot / v_imp
    # (held v_imp of the last small impact) makes up to 2 % here.
    np.testing.assert_allclose(penetration, closed["penetration"], rtol=0.05)


def test_script_runs_and_reports(example, capsys):
    example.main(end_time=0.02, step=1e-5)
    out = capsys.readouterr().out
    assert "callback route" in out and "F_N / statics - 1" in out
