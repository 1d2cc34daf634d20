"""Hostile input to the wear ensembles (issue 35): their own folder, refusing another command's results, the
record of the folder, the keys an ensemble may take as uncertain (decided from the model), the flags that
need --uncertain, a level outside the band, a negative seed, an edited curve.json, a spread of nothing."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from weftsim.cli.commands import EXIT_USAGE, main
from weftsim.errors import WearError
from weftsim.input.scene import SCHEMA, apply_overrides, load_scene, to_file_keys
from weftsim.wear.uncertain import rank_shares
from weftsim.wear.uncertain_keys import check_uncertain_key, uncertain_key_problem

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"
LIMIT_MM = "0.26"  # 0.25 -> 0.26 mm on the reference scene: 3 updates, about a second a prediction
K = "joint_e.wear.wear_coefficient=lognormal(1e-7,0.5)"  # rescaled: one simulated prediction (with --chaos-runs 1)


def _one_error_line(capsys, *words) -> str:
    err = [line for line in capsys.readouterr().err.strip().splitlines() if "error" in line]
    assert len(err) == 1, err
    for word in words:
        assert word in err[0], err[0]
    return err[0]


@pytest.fixture
def captured_outdir(monkeypatch):
    """The directory `weftsim wear` would write to, without running it."""
    seen = {}

    def run(args, scene, outdir, stop):
        seen["outdir"] = Path(outdir)
        return 0

    monkeypatch.setattr("weftsim.cli.wear.run", run)
    return seen


def test_the_ensemble_has_its_own_default_folder(captured_outdir, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert main(["wear", str(REFERENCE), "--hours", "1"]) == 0
    assert captured_outdir["outdir"] == Path("out/reference/wear")
    assert main(["wear", str(REFERENCE), "--uncertain", K, "--limit-clearance-mm", LIMIT_MM]) == 0
    assert captured_outdir["outdir"] == Path("out/reference/wear-ensemble")


def _wear(out: Path, *extra: str) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "weftsim.cli", "wear", str(REFERENCE), "--limit-clearance-mm", LIMIT_MM,
           "--no-plot", "-o", str(out), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


ENSEMBLE = ("--uncertain", K, "--chaos-runs", "1", "--samples", "20", "--jobs", "1")


@pytest.fixture(scope="module")
def wear_and_ensemble(tmp_path_factory):
    """A finished wear prediction and a finished ensemble, each in its own folder."""
    base = tmp_path_factory.mktemp("folders")
    wear, ens = base / "wear", base / "ens"
    first = _wear(wear)
    assert first.returncode == 0, first.stderr
    second = _wear(ens, *ENSEMBLE)
    assert second.returncode == 0, second.stderr
    return wear, ens


def _listing(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.mark.parametrize("into, extra, theirs", [("wear", ENSEMBLE, "`weftsim wear`"),
                                                 ("ens", (), "`weftsim wear --uncertain`")])
def test_neither_replaces_the_others_results(wear_and_ensemble, into, extra, theirs):
    """`wear -o out` then `wear --uncertain ... -o out` (and the reverse): refused, every file kept as it was."""
    folder = dict(zip(("wear", "ens"), wear_and_ensemble))[into]
    before = _listing(folder)
    assert ("wear_state.npz" in before) == (into == "wear") and ("ensemble.json" in before) == (into == "ens")
    again = _wear(folder, *extra)
    assert again.returncode == EXIT_USAGE, again.stderr
    errors = [line for line in again.stderr.splitlines() if "error" in line]
    assert len(errors) == 1 and f"holds the results of {theirs}" in errors[0] and "--force" in errors[0], errors
    assert _listing(folder) == before


def test_the_ensemble_folder_records_its_command_and_scene(wear_and_ensemble):
    _, ens = wear_and_ensemble
    manifest = json.loads((ens / ".weftsim-output.json").read_text())
    assert manifest["kind"] == "wear ensemble" and "--uncertain" in manifest["command"]
    assert manifest["resolved_scene"]["joint_e.clearance_mm"] == pytest.approx(0.25)
    again = load_scene(ens / "scene.toml")  # a scene file of its own: the nominal scene, every key
    assert to_file_keys(again) == {**to_file_keys(load_scene(REFERENCE)), "name": again.name}
    assert "scene.toml" in manifest["files"]


def test_an_edited_curve_is_run_again_not_a_traceback(wear_and_ensemble, tmp_path):
    """A finished job's curve.json with arrays of different lengths (hand-edited): the job is run again."""
    import shutil

    _, ens = wear_and_ensemble
    copy = tmp_path / "ens"
    shutil.copytree(ens, copy)
    curve = next((copy / "jobs").glob("*/curve.json"))
    data = json.loads(curve.read_text())
    data["result"]["hours"] = data["result"]["hours"][:-1]
    curve.write_text(json.dumps(data))
    again = _wear(copy, *ENSEMBLE, "--force")
    assert again.returncode == 0, again.stderr
    assert json.loads((copy / "ensemble.json").read_text())["hours_to_limit"] == \
        json.loads((ens / "ensemble.json").read_text())["hours_to_limit"]


# --- the keys an ensemble may take -------------------------------------------------------------------------

def _fingerprint(scene) -> tuple:
    """Everything a wear ensemble of ``scene`` depends on: the kernel's parameters (geometry, inertia, the
    joints' laws, materials, friction, film at its film temperature, the tape), the speed, Archard's numbers at E
    (the k of the solid contact and of an oil film's asperities, the hardnesses, and the bearing's length and
    radii that spread the worn volume into a depth, weftsim.wear.archard), the film's roughness as it runs in
    over the worn depth (weftsim.wear.extrapolate), the stop-starts (weftsim.wear.duty.with_stops: none when
    the loom does not stop) and the calendar days of a running hour (the life report, weftsim.wear.life)."""
    from weftsim.model.dynamics import pack_parameters
    from weftsim.wear.extrapolate import run_in_roughness

    j = scene.joint
    w = j.wear
    lub = j.lubrication
    asperity = w.asperity_wear_coefficient if lub is not None else None
    running_in = tuple(run_in_roughness(w, lub.roughness, depth) for depth in (0.5e-6, 2e-6, 20e-6)) \
        if lub is not None else ()
    duty = scene.duty
    stops = (duty.stops_per_hour, duty.startup_revolutions, duty.rundown_revolutions) \
        if duty.stops_per_hour > 0.0 else ()
    return (pack_parameters(scene).tobytes(), scene.drive.speed, w.contact_wear_coefficient, asperity,
            w.bearing_hardness, w.journal_hardness, j.bearing_length, j.journal_radius, j.bearing_radius, running_in,
            stops, duty.calendar_days(1.0))


def _nudged(scene, key):
    """``scene`` with ``key`` moved by 5 % of its value, within its range; from an unset or zero value (a
    ``wear_coefficient`` not given, no running-in, no stops) to a small value inside the range."""
    spec = next(k for k in SCHEMA if k.path == key)
    value = to_file_keys(scene)[key]
    if key.endswith("wear.wear_coefficient") and value is None:
        value = scene.joint.wear.contact_wear_coefficient  # the k it would replace
    new = value * 1.05 if value else min(0.05, 0.5 * spec.high)
    if new > spec.high:
        new = value * 0.95
    return apply_overrides(scene, {key: new}, refuse_ideal_keys=False)


FLOAT_KEYS = [k.path for k in SCHEMA if k.kind == "float"]


SCENES = {"reference": lambda: load_scene(REFERENCE),
          "loom-oiled": lambda: load_scene("loom", {"joint_e.lubrication.viscosity_mpa_s": 80.0}),
          # an oil by its grade, its film temperature from the heat balance, and 15 stops an hour
          "loom_oiled": lambda: load_scene("loom_oiled"),
          "loom_tape": lambda: load_scene("loom_tape")}


@pytest.mark.parametrize("scene_name", list(SCENES))
@pytest.mark.parametrize("key", FLOAT_KEYS)
def test_an_accepted_key_changes_what_the_wear_depends_on(scene_name, key):
    """The class, decided from the model: every real-valued key the ensemble accepts changes the kernel's
    parameters, the speed, Archard's numbers at E, the running-in, the stop-starts or the calendar time when it
    changes; every key refused for having no physics, for doing nothing in this scene or for being a setting of
    the prediction changes none of them."""
    scene = SCENES[scene_name]()
    problem = uncertain_key_problem(key, scene)
    if problem is None:
        assert _fingerprint(_nudged(scene, key)) != _fingerprint(scene), key
    elif "members 1-3" in problem:
        return  # changes the driving torque only: test_an_inertia_of_the_driven_chain_does_not_move_joint_e
    elif "not the machine" in problem or "does not change the wear" in problem or "design limit" in problem:
        try:
            nudged = _nudged(scene, key)
        except Exception:  # noqa: BLE001 - a value the scene refuses: nothing to compare
            return
        assert _fingerprint(nudged) == _fingerprint(scene), (key, problem)


def test_the_rod_mass_moves_joint_e():
    """The control of the test below: an inertia beyond the driven chain changes the contact at E."""
    import weftsim

    base = load_scene(REFERENCE, {"drive.revolutions": 0.3})
    heavier = apply_overrides(base, {"inertia.rod_mass_kg": 1.3 * base.inertia.rod_mass})
    runs = [weftsim.simulate(s, "reference", on_warning=lambda text: None) for s in (base, heavier)]
    assert not np.array_equal(runs[0].samples["contact_force_N"], runs[1].samples["contact_force_N"])
    assert uncertain_key_problem("inertia.rod_mass_kg", base) is None


@pytest.mark.parametrize("key", ["inertia.crank_inertia_kg_m2", "inertia.coupler_mass_kg", "inertia.rocker_mass_kg",
                                 "inertia.rocker_com_mm", "inertia.rocker_inertia_kg_m2"])
def test_an_inertia_of_the_driven_chain_does_not_move_joint_e(key):
    """Members 1-3 turn with the constant-speed crank: their inertia changes at most the driving torque, not the
    contact at E (bit for bit), so the ensemble refuses it; the rod's mass, accepted, changes the contact."""
    import weftsim

    base = load_scene(REFERENCE, {"drive.revolutions": 0.3})
    value = to_file_keys(base)[key]
    heavier = apply_overrides(base, {key: 1.3 * value if value else 5.0})
    runs = [weftsim.simulate(s, "reference", on_warning=lambda text: None) for s in (base, heavier)]
    assert np.array_equal(runs[0].samples["contact_force_N"], runs[1].samples["contact_force_N"])
    assert "members 1-3" in uncertain_key_problem(key, base)


@pytest.mark.parametrize("key, words", [
    ("joint_f.lubrication.viscosity_mpa_s", ["joint F is ideal", "change nothing"]),
    ("joint_f.clearance_mm", ["make it loose"]),
    ("output.sample_deg", ["output grid"]),
    ("drive.revolutions", ["settle_revolutions"]),
    ("revolutions", ["settle_revolutions"]),  # the short name resolves first
    ("solver.reference.rtol", ["how closely"]),
    ("limits.max_steps", ["whole-number"]),
    ("joint_e.law", ["a name"]),
    ("joint_e.bearing_material.max_pressure_mpa", ["design limit"]),
    ("joint_e.friction_velocities_m_s", ["a list of numbers"]),
    ("joint_e.lubrication.viscosity_mpa_s", ["joint E is dry"]),
    ("joint_e.bogus", ["unknown scene key 'joint_e.bogus'"]),
])
def test_a_key_that_cannot_spread_the_wear_is_refused_in_one_line(key, words):
    with pytest.raises(WearError) as err:
        check_uncertain_key(key, load_scene(REFERENCE))
    text = str(err.value)
    assert "\n" not in text and "weftsim list" not in text
    for word in words:
        assert word in text, text


@pytest.mark.parametrize("name, key", [("clearance_mm", "joint_e.clearance_mm"), ("speed_rpm", "drive.speed_rpm"),
                                       ("wear_coefficient", "joint_e.wear.wear_coefficient"),
                                       ("restitution", "joint_e.restitution")])
def test_the_short_names_of_set_are_taken(name, key):
    assert check_uncertain_key(name, load_scene(REFERENCE)) == key


def test_an_ensemble_takes_the_short_name_end_to_end(tmp_path):
    from weftsim.wear.ensemble import wear_ensemble

    data = wear_ensemble(load_scene(REFERENCE), ["wear_coefficient=lognormal(1e-7,0.5)"], 20, 0.26e-3,
                         tmp_path / "ens", jobs=1, chaos_runs=1, figures=False)
    assert data["method"]["rescaled"] == ["joint_e.wear.wear_coefficient"]
    assert data["uncertain"] == ["joint_e.wear.wear_coefficient=lognormal(1e-07,0.5)"]


def test_a_spread_of_nothing_has_no_shares():
    """Every sample the same (a key without effect, all censored): no input takes a share, and no warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        shares = rank_shares({"a": np.linspace(0, 1, 50), "b": np.ones(50)}, np.full(50, 3.0))
    assert shares == {"a": (0.0, 0.0), "b": (0.0, 0.0)}


# --- the flags ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("flags", [["--samples", "50"], ["--level-mm", "0.255"], ["--design-points",
                                   "speed_rpm=5"], ["--chaos-runs", "2"], ["--seed", "3"], ["--jobs", "2"]])
def test_ensemble_flags_without_uncertain_are_refused(capsys, tmp_path, flags):
    assert main(["wear", str(REFERENCE), "--hours", "1", "-o", str(tmp_path / "w"), *flags]) == EXIT_USAGE
    _one_error_line(capsys, flags[0], "need(s) --uncertain")
    assert not (tmp_path / "w").exists()


@pytest.mark.parametrize("level", ["0.3", "0.25", "0.2", "0.26"])
def test_a_level_outside_the_band_is_refused(capsys, tmp_path, level):
    argv = ["wear", str(REFERENCE), "--uncertain", K, "--limit-clearance-mm", LIMIT_MM, "--level-mm", level,
            "-o", str(tmp_path / "e")]
    assert main(argv) == EXIT_USAGE
    _one_error_line(capsys, f"--level-mm {float(level):g}", "between the starting clearance 0.25 mm and the limit 0.26")
    assert not (tmp_path / "e").exists()


def test_a_negative_seed_is_refused_before_any_simulation(capsys, tmp_path):
    argv = ["wear", str(REFERENCE), "--uncertain", K, "--limit-clearance-mm", LIMIT_MM, "--seed", "-1",
            "-o", str(tmp_path / "e")]
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == EXIT_USAGE
    assert "--seed: must be a whole number >= 0, got '-1'" in capsys.readouterr().err
    with pytest.raises(WearError, match="--seed must be a whole number >= 0"):
        from weftsim.wear.ensemble import wear_ensemble

        wear_ensemble(load_scene(REFERENCE), [K], 20, 0.26e-3, tmp_path / "e", seed=-1)
    assert not (tmp_path / "e").exists()


def test_a_key_that_counts_only_beside_another_uncertain_key_is_taken_with_it():
    """A stop's transients do nothing on a loom that does not stop, unless its stop rate is uncertain too (then
    every sample with stops wears them); the same for the running-in depth beside its roughness."""
    reference = load_scene(REFERENCE)
    with pytest.raises(WearError, match="does not stop"):
        check_uncertain_key("duty.startup_revolutions", reference)
    assert check_uncertain_key("startup_revolutions", reference, ("stops_per_hour",)) == "duty.startup_revolutions"
    oiled = load_scene("loom_oiled")
    with pytest.raises(WearError, match="no run_in_roughness_um"):
        check_uncertain_key("joint_e.wear.run_in_depth_um", oiled)
    assert check_uncertain_key("joint_e.wear.run_in_depth_um", oiled, ("joint_e.wear.run_in_roughness_um",)) \
        == "joint_e.wear.run_in_depth_um"


def test_a_bound_too_few_samples_give_is_not_called_censored():
    """With 20 samples the 90 % order-statistic interval has no lower bound for p10 (P(no sample below the
    true p10) = 0.9^20 = 0.12 > 0.05) and no upper bound for p90; `weftsim wear --uncertain --samples 20`
    printed both as the censored "> 1e+05 h" ("p10: 1.161 h (90 % interval > 1e+05 h - 1.415 h)").  A bound
    beyond the horizon (among censored samples) still reads "> H h"."""
    from scipy import stats

    from weftsim.wear.censored import text_interval
    from weftsim.wear.ensemble import quantile_table

    assert stats.binom.ppf(0.05, 20, 0.1) == 0 and stats.binom.ppf(0.95, 20, 0.9) + 1 > 20  # no rank in 1..20
    table = quantile_table(np.arange(1.0, 21.0), 1e5)
    p10, p90 = table["p10"], table["p90"]
    assert p10["low"] is None and p10["low_beyond_hours"] is None and p10["high"] == 5.0
    assert p90["high"] is None and p90["high_beyond_hours"] is None and p90["low"] == 16.0
    assert text_interval(p10, 20) == "0 h - 5 h: 20 samples are too few for a lower bound"
    assert text_interval(p90, 20) == "16 h - unbounded: 20 samples are too few for an upper bound"
    # 100 samples, the last 20 censored at 1e5 h: p90's bounds lie among them, beyond the horizon.
    censored = quantile_table(np.r_[np.arange(1.0, 81.0), [np.inf] * 20], 1e5)["p90"]
    assert censored["censored"] and censored["low_beyond_hours"] == censored["high_beyond_hours"] == 1e5
    assert text_interval(censored, 100) == "> 1e+05 h - > 1e+05 h"


def test_the_dry_friction_of_an_oiled_joint_is_refused():
    """In oil the solids' contact carries the boundary coefficient (weftsim.physics.joint): the dry joint's
    friction coefficient is not read, so it cannot spread the wear; the boundary coefficient may."""
    scene = SCENES["loom-oiled"]()
    with pytest.raises(WearError) as err:
        check_uncertain_key("joint_e.friction_coefficient", scene)
    assert "boundary_friction_coefficient" in str(err.value) and "\n" not in str(err.value)
    assert uncertain_key_problem("joint_e.lubrication.boundary_friction_coefficient", scene) is None
