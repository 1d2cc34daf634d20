"""Files weftsim writes and reads back, round four (issue 35): a result.npz edited to drop or add a joint's
film channels, a wear state with its checksum removed, an empty or unknown scene table, a full disk during
``weftsim wear``: each one line, nothing lost, never read as another run."""

from __future__ import annotations

import errno
import json
import shutil

import numpy as np
import pytest

import weftsim
from weftsim.cli.commands import main
from weftsim.post.results import LUBRICATION_CHANNELS
from weftsim.wear import predict_to_directory
from weftsim.wear.store import STATE, StateMismatch


def _arrays(path):
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def _npz(path, arrays):
    with open(path, "wb") as handle:
        np.savez_compressed(handle, **arrays)
    return path


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """A dry and a lubricated short run of the reference engine, saved."""
    base = tmp_path_factory.mktemp("saved")
    out = {}
    for name, overrides in (("dry", {}), ("oiled", {"joint_e.lubrication.viscosity_mpa_s": 80.0})):
        scene = weftsim.load_scene("reference", {**overrides, "drive.revolutions": 0.2})
        result = weftsim.simulate(scene, "reference", on_warning=lambda text: None)
        out[name] = weftsim.save_result(result, base / f"{name}.npz")
    return out


def _refused(path, *words):
    with pytest.raises(weftsim.OutputError) as caught:
        weftsim.load_result(path)
    text = str(caught.value)
    assert "\n" not in text, text
    for word in words:
        assert word in text, text


def test_both_load_as_saved(saved):
    assert "film_ratio" in weftsim.load_result(saved["oiled"]).samples
    assert "film_ratio" not in weftsim.load_result(saved["dry"]).samples


def test_a_lubricated_result_without_its_film_channels_is_refused(tmp_path, saved):
    arrays = {k: v for k, v in _arrays(saved["oiled"]).items() if k.partition("/")[2] not in LUBRICATION_CHANNELS}
    _refused(_npz(tmp_path / "r.npz", arrays), "joint_e is lubricated but it holds no film channels")


def test_a_dry_result_with_film_channels_is_refused(tmp_path, saved):
    arrays = _arrays(saved["dry"])
    for table in ("samples", "steps"):
        for name in LUBRICATION_CHANNELS:
            arrays[f"{table}/{name}"] = np.zeros_like(arrays[f"{table}/time_s"])
    _refused(_npz(tmp_path / "r.npz", arrays), "film channels of joint_e", "dry (no [joint_e.lubrication])")


@pytest.mark.parametrize("table, words", [
    ("[joint_e.lubrication]", ["[joint_e.lubrication] is empty", "viscosity_mpa_s", "leave the table out"]),
    ("[joint_e.lubricaton]", ["unknown table [joint_e.lubricaton]", "did you mean [joint_e.lubrication]?"]),
    ("[solver.referenc]", ["unknown table [solver.referenc]", "did you mean [solver.reference]?"]),
])
def test_an_empty_table_is_not_silently_the_dry_joint(tmp_path, table, words):
    path = tmp_path / "s.toml"
    path.write_text(f'extends = "reference"\n{table}\n')
    with pytest.raises(weftsim.SceneError) as err:
        weftsim.load_scene(path)
    for word in words:
        assert word in str(err.value), str(err.value)


def test_an_empty_joint_f_or_wear_table_is_still_fine(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('extends = "reference"\n[joint_f]\n[joint_e.wear]\n')
    assert weftsim.load_scene(path).joint_f.is_ideal


# --- wear ------------------------------------------------------------------------------------------------

HOURS = 4.0  # the reference loom: 5 updates, ~2 s


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    scene = weftsim.load_scene("reference")
    outdir = tmp_path_factory.mktemp("wear") / "done"
    predict_to_directory(scene, HOURS, outdir, figures=False)
    return scene, outdir


def test_a_state_without_its_checksum_is_not_resumed(finished, tmp_path):
    """Every state naming its joints was written with a digest: one without it was edited, not old."""
    scene, outdir = finished
    copy = tmp_path / "w"
    shutil.copytree(outdir, copy)
    arrays = {k: v for k, v in _arrays(copy / STATE).items() if k != "digest"}
    with open(copy / STATE, "wb") as handle:
        np.savez(handle, **arrays)
    with pytest.raises(StateMismatch) as err:
        predict_to_directory(scene, 2 * HOURS, copy, figures=False)
    assert "checksum ('digest') is missing" in str(err.value) and "\n" not in str(err.value)


def test_a_full_disk_during_wear_is_one_line_and_keeps_the_state(monkeypatch, tmp_path, capsys):
    """The third state write fails with ENOSPC: `weftsim wear` ends with one line, the state on disk is the
    second update's, whole, and the same command resumes from it once there is room."""
    from weftsim.wear import store

    real = store.save_state
    calls = []

    def full(outdir, scene, updates):
        calls.append(len(updates))
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(outdir, scene, updates)

    monkeypatch.setattr(store, "save_state", full)
    out = tmp_path / "w"
    argv = ["wear", "reference", "--hours", str(HOURS), "--no-plot", "-o", str(out)]
    assert main(argv) != 0
    err = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert len(err) == 1 and "No space left on device" in err[0] and "run the same command again" in err[0], err
    kept = store.load_state(out, weftsim.load_scene("reference"))
    assert len(kept) == calls[1]  # the last state that was written, whole
    monkeypatch.setattr(store, "save_state", real)
    assert main(argv) == 0
    assert json.loads((out / "wear.json").read_text())["hours_reached"] == pytest.approx(HOURS)
