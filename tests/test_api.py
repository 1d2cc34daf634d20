"""The Python interface (weftsim.load_scene, simulate, save_result, load_result, load_sweep,
bundled_scenes) and its one exception hierarchy."""

import dataclasses
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import weftsim
from weftsim import errors
from weftsim.post.results import CHANNELS, scene_channels

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
PAPER_CASES = ("paper/clearance_0p01mm_400rpm", "paper/clearance_0p25mm_400rpm", "paper/clearance_0p50mm_400rpm",
               "paper/speed_300rpm_c0p25mm", "paper/speed_500rpm_c0p25mm", "paper/speed_800rpm_c0p25mm")


def same_scene(a, b):
    """Scenes equal in everything but ``source`` (the path each was read from)."""
    return dataclasses.replace(a, source="") == dataclasses.replace(b, source="")


# --- scenes --------------------------------------------------------------------------------------------


def test_every_scene_file_of_models_is_bundled_under_its_path_name():
    names = weftsim.bundled_scenes()
    assert names == sorted(p.relative_to(MODELS).with_suffix("").as_posix() for p in MODELS.rglob("*.toml"))
    assert {"reference", "loom", "ideal", *PAPER_CASES} <= set(names)
    for name in names:
        assert same_scene(weftsim.load_scene(name), weftsim.load_scene(MODELS / f"{name}.toml"))


def test_overrides_and_flags_are_in_file_units():
    scene = weftsim.load_scene("reference", {"joint_e.restitution": 0.8, "solver.reference.rtol": 1e-7},
                               clearance_mm=0.5, speed_rpm=600, revolutions=3, law="flores")
    # File units in, SI out: 0.5 mm -> 5e-4 m, 600 rpm -> 20 pi rad/s; one multiplication each, so the only
    # difference is its rounding (<= 1 ulp, 1.1e-16 relative): 1e-15 leaves a margin of ten.
    assert scene.joint.clearance == pytest.approx(5e-4, rel=1e-15)
    assert scene.drive.speed == pytest.approx(600 * 2 * math.pi / 60, rel=1e-15)
    assert (scene.drive.revolutions, scene.joint.law, scene.joint.restitution) == (3, "flores", 0.8)
    assert scene.reference_solver.rtol == 1e-7
    assert same_scene(weftsim.load_scene("paper/clearance_0p50mm_400rpm"),
                      weftsim.load_scene("reference", clearance_mm=0.5, overrides={"name": "clearance_0p50mm_400rpm"}))


@pytest.mark.parametrize("call, words", [
    (lambda: weftsim.load_scene("reference", clearence_mm=0.5), ["unknown scene flag 'clearence_mm'",
                                                                 "did you mean clearance_mm"]),
    (lambda: weftsim.load_scene("reference", {"joint_e.clearence_mm": 0.5}),
     ["overrides", "unknown key 'joint_e.clearence_mm'", "did you mean 'joint_e.clearance_mm'"]),
    (lambda: weftsim.load_scene("reference", {"joint_e.clearance_mm": 0.4}, clearance_mm=0.5),
     ["'joint_e.clearance_mm' is given twice"]),
    (lambda: weftsim.load_scene("reference", clearance_mm=-1), ["joint_e.clearance_mm", ">= 0", "-1"]),
    (lambda: weftsim.load_scene("referense"), ["no bundled scene", "did you mean reference"]),
    (lambda: weftsim.load_scene("paper/clearance_0p5mm_400rpm"), ["did you mean paper/clearance_0p50mm_400rpm"]),
])
def test_bad_scene_input_is_a_scene_error_with_the_closest_spelling(call, words):
    with pytest.raises(weftsim.SceneError) as caught:
        call()
    for word in words:
        assert word in str(caught.value), (word, str(caught.value))
    assert "\n" not in str(caught.value)


def test_a_file_of_ones_own_extends_a_bundled_scene_by_name(tmp_path):
    own = tmp_path / "mine.toml"
    own.write_text('extends = "paper/clearance_0p50mm_400rpm"\nname = "mine"\n[drive]\nspeed_rpm = 500\n')
    scene = weftsim.load_scene(own)
    expected = weftsim.load_scene("paper/clearance_0p50mm_400rpm", speed_rpm=500, overrides={"name": "mine"})
    assert same_scene(scene, expected)
    own.write_text('extends = "referense"\n')
    with pytest.raises(weftsim.SceneError, match="key 'extends' = 'referense'.*did you mean reference"):
        weftsim.load_scene(own)


def test_a_file_of_the_same_name_as_a_bundled_scene_wins(tmp_path, monkeypatch):
    """A user's file is never shadowed: 'reference' in the current directory is that file."""
    text = (MODELS / "reference.toml").read_text().replace('name = "reference"', 'name = "local"')
    (tmp_path / "reference").write_text(text.replace("speed_rpm = 400.0", "speed_rpm = 300.0"))
    monkeypatch.chdir(tmp_path)
    scene = weftsim.load_scene("reference")
    # rpm -> rad/s is one multiplication: 1e-15 sits ten times above its rounding, as in the test above.
    assert scene.name == "local" and scene.drive.speed == pytest.approx(300 * math.pi / 30, rel=1e-15)


# --- simulate, results ---------------------------------------------------------------------------------


def test_engine_names():
    from weftsim.api import resolve_engine

    assert resolve_engine("auto") == weftsim.DEFAULT_ENGINE == "exudyn"
    with pytest.raises(weftsim.EngineError, match="engine must be one of auto, exudyn, reference, got 'adams'"):
        weftsim.simulate("ideal", engine="adams")


def test_simulate_a_bundled_name_reproduces_the_check_values():
    """docs/physics.md section 1: stroke 1.052348 m, rapier velocity +-21.754 m/s at 400 rpm (ideal joints)."""
    result = weftsim.simulate(weftsim.load_scene("ideal", revolutions=1), engine="reference")
    assert result.ok and result.engine == "reference"
    s, v = result.steps["rapier_displacement_m"], result.steps["rapier_velocity_m_s"]
    # The check values have 6-7 digits; the tolerances are half a unit of their last digit.  The steps are
    # 0.1 deg of the closed form, which samples these flat extrema to ~1e-8 relative, far below that.
    assert s.max() - s.min() == pytest.approx(1.052348, abs=5e-7)
    assert v.max() == pytest.approx(21.754, abs=5e-4)


def test_to_pandas_holds_every_channel_of_both_tables():
    pytest.importorskip("pandas")
    result = weftsim.simulate(weftsim.load_scene("ideal", revolutions=0.5), engine="reference")
    for which, table in (("samples", result.samples), ("steps", result.steps)):
        frame = result.to_pandas(which)
        assert list(frame.columns) == list(CHANNELS)
        assert len(frame) == table["time_s"].size
        for name in CHANNELS:
            assert np.array_equal(frame[name].to_numpy(), table[name])
        assert frame.attrs == {"scene": "ideal", "engine": "reference", "status": "success", "table": which}
    with pytest.raises(ValueError, match="'samples' or 'steps'"):
        result.to_pandas("sample")


def test_missing_optional_packages_name_the_extra(monkeypatch, tmp_path):
    result = weftsim.simulate(weftsim.load_scene("ideal", revolutions=0.1), engine="reference")
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now raises ImportError
    monkeypatch.setitem(sys.modules, "xarray", None)
    from weftsim.errors import install_command

    hint = re.escape(install_command("data"))  # 'weftsim[data]' installed, '.[data]' in a checkout
    with pytest.raises(weftsim.MissingExtra, match=r"needs pandas.*" + hint):
        result.to_pandas()
    (tmp_path / "sweep.json").write_text("{}")
    with pytest.raises(weftsim.MissingExtra, match=r"load_sweep needs xarray.*" + hint):
        weftsim.load_sweep(tmp_path)


@pytest.mark.parametrize("name", ["paper/clearance_0p50mm_400rpm", "clearance_ef"])
def test_a_saved_result_loads_back_equal(tmp_path, name):
    """Lossless: both tables bit for bit (joint F's channels too), the scene, statistics, events,
    plausibility and path; the pandas table has every channel."""
    scene = weftsim.load_scene(name, revolutions=0.5)
    result = weftsim.simulate(scene, engine="reference")
    assert result.steps["time_s"].size > result.samples["time_s"].size  # the per-step table is the larger one
    path = weftsim.save_result(result, tmp_path / "run.npz")
    loaded = weftsim.load_result(path)
    assert loaded.scene == result.scene  # every SI value exactly, not via the file's units
    assert loaded.channel_names == result.channel_names
    assert list(result.to_pandas("steps").columns) == list(result.channel_names)
    for table in ("samples", "steps"):
        for name in result.channel_names:
            assert np.array_equal(getattr(loaded, table)[name], getattr(result, table)[name]), (table, name)
    for field in ("engine", "status", "message", "solver_stats", "events", "plausibility", "path"):
        assert getattr(loaded, field) == getattr(result, field), field
    assert loaded.first_contact_angle_deg == result.first_contact_angle_deg


def test_a_file_that_is_not_a_result_is_an_output_error(tmp_path):
    with pytest.raises(weftsim.OutputError, match="not found"):
        weftsim.load_result(tmp_path / "none.npz")
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(weftsim.OutputError, match="cannot be read as a weftsim result"):
        weftsim.load_result(tmp_path / "text.npz")
    np.savez(tmp_path / "other.npz", meta=np.array('{"format": "something/2"}'))
    with pytest.raises(weftsim.OutputError, match="not a weftsim result of format weftsim-result/1"):
        weftsim.load_result(tmp_path / "other.npz")


def test_both_engines_from_one_short_script():
    """The README's script: a bundled scene, the clearance overridden, both engines, a pandas table each.
    The first contact is the reproducible quantity of a clearance run (docs/physics.md section 6)."""
    pytest.importorskip("pandas")
    scene = weftsim.load_scene("reference", clearance_mm=0.5, revolutions=1)
    results = {engine: weftsim.simulate(scene, engine, raise_on_failure=True) for engine in ("reference", "exudyn")}
    for engine, result in results.items():
        table = result.to_pandas("steps")
        # Every channel the scene has (the loose joint E adds its load joint_force_N), the same on both engines.
        assert list(table.columns) == list(scene_channels(scene)) and table["contact_force_N"].max() > 0
        # A dry frictionless joint carries exactly its contact force (weftsim.joint.load); Exudyn measures the
        # connector's force, whose magnitude is the law's F_N to round-off (1e-9 relative of ~10 kN peaks).
        np.testing.assert_allclose(table["joint_force_N"], table["contact_force_N"], rtol=1e-9, atol=1e-6)
        # The first step flagged in contact is the onset's step: at most one step after the located onset.
        flagged = table.loc[table["in_contact"] > 0, "crank_angle_deg"].iloc[0]
        steps_deg = np.diff(table["crank_angle_deg"].to_numpy())
        assert result.first_contact_angle_deg <= flagged <= result.first_contact_angle_deg + steps_deg.max()
    # `weftsim compare` holds the engines to the scene's first-contact tolerance (0.1 deg); so does the API.
    gap = abs(results["exudyn"].first_contact_angle_deg - results["reference"].first_contact_angle_deg)
    assert gap <= math.degrees(scene.compare.first_contact_angle)


def test_raise_on_failure_keeps_the_partial_result():
    scene = weftsim.load_scene("reference", {"limits.max_steps": 5}, revolutions=0.5)
    result = weftsim.simulate(scene, engine="reference")
    assert not result.ok and result.message
    with pytest.raises(weftsim.RunFailed) as caught:
        weftsim.simulate(scene, engine="reference", raise_on_failure=True)
    assert caught.value.result is not None and caught.value.result.status == "failed"
    assert caught.value.exit_status == 3


# --- sweeps ---------------------------------------------------------------------------------------------


def test_a_sweep_loads_as_a_labelled_grid(tmp_path):
    """The fake engine of test_sweep has closed-form peaks: the grid holds them at the right coordinates."""
    pytest.importorskip("xarray")
    from test_sweep import fake_peaks, sweep

    sweep(tmp_path, ["clearance_mm=0.5,0.01,0.25", "speed_rpm=300,600"], jobs=1)
    (tmp_path / "clearance_mm=0.25,speed_rpm=600" / "cell.json").unlink()  # as if that cell had not run yet
    grid = weftsim.load_sweep(tmp_path)
    assert grid.sizes == {"clearance_mm": 3, "speed_rpm": 2}
    assert list(grid["clearance_mm"].values) == [0.01, 0.25, 0.5]  # ascending, whatever the --vary order
    assert grid["clearance_mm"].attrs["scene_key"] == "joint_e.clearance_mm"
    assert grid.attrs["engine"] == "test_sweep:fake_solve"
    for c in (0.01, 0.25, 0.5):
        for rpm in (300, 600):
            cell = grid.sel(clearance_mm=c, speed_rpm=rpm)
            if (c, rpm) == (0.25, 600):
                assert str(cell["status"].values) == "not run"
                assert np.isnan(cell["contact_force_N_rev1_peak"].values)
                continue
            expected = fake_peaks(c, rpm)
            assert str(cell["status"].values) == "success"
            # cell.json keeps full double precision and fake_peaks evaluates the same closed form on the same
            # grid: only round-off in a different order of operations (~1e-15) remains, 1e-12 is far above it.
            assert float(cell["contact_force_N_rev1_peak"]) == pytest.approx(expected["contact"], rel=1e-12)
            assert float(cell["rapier_acceleration_m_s2_rev1_peak"]) == pytest.approx(expected["acceleration"],
                                                                                     rel=1e-12)
    with pytest.raises(weftsim.SweepError, match="not a sweep directory"):
        weftsim.load_sweep(tmp_path / "clearance_mm=0.01,speed_rpm=300")


# --- the interface itself -------------------------------------------------------------------------------


def test_every_error_is_a_weftsim_error_and_the_builtin_a_caller_expects():
    expected = {errors.SceneError: ValueError, errors.EngineError: ValueError, errors.OutputError: OSError,
                errors.WriteFailed: OSError, errors.RunFailed: RuntimeError, errors.SweepError: ValueError,
                errors.StudyError: ValueError, errors.SimulationFailed: ValueError, errors.MissingExtra: ImportError}
    for cls, builtin in expected.items():
        assert issubclass(cls, weftsim.WeftsimError) and issubclass(cls, builtin), cls
    from weftsim.cli.commands import CliError
    from weftsim.post.output import OutputError
    from weftsim.input.scene import SceneError
    from weftsim.studies import StudyError
    from weftsim.sweep import SweepError

    assert issubclass(CliError, weftsim.WeftsimError)
    assert (SceneError, OutputError, StudyError, SweepError) == (errors.SceneError, errors.OutputError,
                                                                 errors.StudyError, errors.SweepError)


def test_help_shows_the_interface_with_annotations():
    import inspect
    import pydoc

    text = pydoc.render_doc(weftsim, renderer=pydoc.plaintext)
    for name in ("load_scene", "simulate", "save_result", "load_result", "load_sweep", "bundled_scenes"):
        assert name in text
        function = getattr(weftsim, name)
        assert function.__doc__ and len(function.__doc__.splitlines()) > 1, name  # more than a one-liner
        signature = inspect.signature(function)
        assert signature.return_annotation is not inspect.Signature.empty, name
        assert all(p.annotation is not inspect.Parameter.empty for p in signature.parameters.values()), name
    assert set(weftsim.__all__) <= set(dir(weftsim))
