"""``weftsim wear`` resuming from a damaged or edited ``wear_state.npz`` (issue 24): one clear line naming the
file and what to do, never a traceback, never a resumed prediction that extrapolates from wrong numbers;
an intact interrupted state still resumes to the same answer as a run that was never interrupted."""

import os
import shutil

import numpy as np
import pytest

import weftsim
from weftsim.cli.commands import main
from weftsim.errors import OutputError
from weftsim.wear import predict_to_directory
from weftsim.wear.store import STATE, StateMismatch

HOURS = 4.0  # four hours of the reference loom: 5 updates, ~2 s


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished prediction's directory and its state's arrays."""
    scene = weftsim.load_scene("reference")
    outdir = tmp_path_factory.mktemp("wear") / "done"
    summary = predict_to_directory(scene, HOURS, outdir, figures=False)
    with np.load(outdir / STATE) as data:
        arrays = {k: data[k] for k in data.files}
    assert arrays["hours"].size >= 3  # the history checks below need updates to compare
    return scene, outdir, arrays, summary


def _copy(finished, tmp_path, arrays=None, raw=None, directory=False):
    """A copy of the finished directory whose state is replaced by ``arrays``, ``raw`` bytes or a directory."""
    outdir = tmp_path / "w"
    shutil.copytree(finished[1], outdir)
    state = outdir / STATE
    state.unlink()
    if directory:
        state.mkdir()
    elif raw is not None:
        state.write_bytes(raw)
    else:
        with open(state, "wb") as handle:
            np.savez(handle, **arrays)
    return outdir


def _refused(scene, outdir, *words, hours=HOURS):
    with pytest.raises(StateMismatch) as caught:
        predict_to_directory(scene, hours, outdir, figures=False)
    text = str(caught.value)
    assert "\n" not in text and STATE in text, text
    for word in words:
        assert word in text, text
    assert "check the materials" not in text
    return text


def _edited(arrays, name, change):
    out = dict(arrays)
    out[name] = np.array(arrays[name], copy=True)
    change(out[name])
    return out


@pytest.mark.parametrize("kind, words", [
    ("empty", ["empty (0 bytes"]),
    ("truncated", ["not an NPZ (ZIP) archive, or a truncated one"]),
    ("garbage", ["not an NPZ (ZIP) archive"]),
    ("directory", ["it is a directory"]),
])
def test_a_damaged_state_file_is_one_line(finished, tmp_path, kind, words):
    raw = (finished[1] / STATE).read_bytes()
    outdir = _copy(finished, tmp_path, raw={"empty": b"", "truncated": raw[: len(raw) // 2],
                                            "garbage": os.urandom(3000), "directory": None}[kind],
                   directory=kind == "directory")
    _refused(finished[0], outdir, *words, f"delete {STATE} to start the prediction over")


@pytest.mark.parametrize("name, change, words", [
    ("bearing", lambda a: a.pop("bearing_e"), ["lacks bearing_e"]),
    ("response", lambda a: a.pop("response"), ["lacks response"]),
    ("shape", lambda a: a.update(bearing_e=a["bearing_e"][:, :100]), ["'bearing_e' has shape", "profile_points"]),
    ("hours", lambda a: a.update(hours=a["hours"][:-1]), ["has shape"]),
    ("scalar", lambda a: a.update(hours=np.array(3.0)), ["'hours' has shape ()"]),
    ("text", lambda a: a.update(bearing_e=a["bearing_e"].astype(str)), ["not numbers"]),
    ("other joint", lambda a: a.update(bearing_f=a["bearing_e"]), ["bearing_f", "does not wear"]),
])
def test_a_state_missing_an_array_or_of_the_wrong_shape(finished, tmp_path, name, change, words):
    arrays = dict(finished[2])
    change(arrays)
    _refused(finished[0], _copy(finished, tmp_path, arrays), "damaged wear state", *words)


def test_a_nan_profile_is_named_not_blamed_on_the_materials(finished, tmp_path):
    arrays = _edited(finished[2], "bearing_e", lambda b: b.__setitem__((-1, 5), np.nan))
    _refused(finished[0], _copy(finished, tmp_path, arrays), "'bearing_e' holds a value that is not finite")


@pytest.mark.parametrize("name, change, words", [
    # The last update's worn depth raised 10 %: not what the update before it implies.
    ("bearing_e", lambda b: b.__setitem__(-1, 1.1 * b[-1]), ["update", "bearing_e is not what update"]),
    ("hours", lambda h: h.__setitem__(-1, 0.5 * h[-1]), ["hours is not what update"]),
    ("step_revolutions", lambda n: n.__setitem__(1, 1e9), ["is not what update 1 implies"]),
    ("rate_bearing_e", lambda r: r.__setitem__(1, 1.1 * r[1]), ["bearing_e is not what update 1 implies"]),
    ("volume_rate_e", lambda v: v.__setitem__(1, 2.0 * v[1]), ["volume_rate_e is not the volume"]),
    ("bearing_e", lambda b: b.__setitem__(1, -b[1]), ["negative value"]),
])
def test_a_hand_edited_state_is_refused_by_its_own_history(finished, tmp_path, name, change, words):
    arrays = _edited(finished[2], name, change)
    _refused(finished[0], _copy(finished, tmp_path, arrays), "damaged or edited", *words)


def _interrupted(arrays, dropped):
    """The state as a Ctrl-C leaves it ``dropped`` updates before the end (weftsim writes the checksum with it)."""
    return _signed({k: (v[:-dropped] if k != "scene" else v) for k, v in arrays.items() if k != "digest"})


def _signed(arrays):
    """``arrays`` with the checksum of their numbers as they are."""
    from weftsim.wear.resume import digest

    out = {k: v for k, v in arrays.items() if k != "digest"}
    out["digest"] = np.array(digest(out))
    return out


def test_consistently_scaled_rates_break_the_update_rule(finished, tmp_path):
    """All three rates of an update whose N the update rule set, scaled by 1.1 (volumes and the hardness
    ratio still agree): its N is then more than max_clearance_change allows."""
    arrays = _interrupted(finished[2], 2)
    for name in ("rate_bearing_e", "rate_journal_e", "volume_rate_e"):
        arrays[name] = arrays[name].copy()
        arrays[name][-1] *= 1.1
    _refused(finished[0], _copy(finished, tmp_path, _signed(arrays)),
             "more revolutions than joint_e.wear.max_clearance_change")


def test_edited_last_rates_are_not_extrapolated(finished, tmp_path):
    """The last update's rates scaled consistently where its N was cut to the hours left (the update rule
    cannot tell): the resume simulates that update again, so the answer is the uninterrupted one."""
    arrays = _interrupted(finished[2], 1)
    for name in ("rate_bearing_e", "rate_journal_e", "volume_rate_e"):
        arrays[name] = arrays[name].copy()
        arrays[name][-1] *= 1.1
    summary = predict_to_directory(finished[0], HOURS, _copy(finished, tmp_path, _signed(arrays)), figures=False)
    assert summary["final_effective_clearance_e_mm"] == finished[3]["final_effective_clearance_e_mm"]
    assert summary["wear_volume_mm3"] == finished[3]["wear_volume_mm3"]


def test_an_edited_response_statistic_fails_the_checksum(finished, tmp_path):
    arrays = _edited(finished[2], "response", lambda r: r.__setitem__((1, 0), 2.0 * r[1, 0]))
    _refused(finished[0], _copy(finished, tmp_path, arrays), "checksum")


@pytest.mark.parametrize("overrides", [{"joint_e.clearance_mm": 0.3}, {"joint_e.wear.profile_points": 180}])
def test_a_state_of_another_scene_is_refused(finished, tmp_path, overrides):
    """Named as another scene's, also where its arrays no longer fit (fewer profile points): the directory's
    record of its scene refuses it first, naming the key that differs (weftsim.post.record)."""
    other = weftsim.load_scene("reference", overrides)
    with pytest.raises(OutputError) as caught:
        predict_to_directory(other, HOURS, _copy(finished, tmp_path, finished[2]), figures=False)
    text = str(caught.value)
    assert "\n" not in text and "another scene" in text and next(iter(overrides)) in text, text


def test_fewer_hours_than_stored_says_so(finished, tmp_path):
    _refused(finished[0], _copy(finished, tmp_path, finished[2]), f"reaches {HOURS:g} h", "--hours 1 asked for",
             hours=1.0)


def test_an_interrupted_state_resumes_to_the_uninterrupted_answer(finished, tmp_path):
    """The two last updates dropped, as after a Ctrl-C: the resume recomputes them, bit for bit."""
    arrays = _signed(_interrupted(finished[2], 2))
    summary = predict_to_directory(finished[0], HOURS, _copy(finished, tmp_path, arrays), figures=False)
    for key in ("final_effective_clearance_e_mm", "wear_volume_mm3", "updates", "hours_reached"):
        assert summary[key] == finished[3][key], key


def test_the_command_line_says_it_in_one_line(finished, tmp_path, capsys):
    outdir = _copy(finished, tmp_path, raw=b"")
    assert main(["wear", "reference", "--hours", str(HOURS), "-o", str(outdir), "--no-plot"]) == 2
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if "error" in line]
    assert len(errors) == 1 and errors[0].startswith("weftsim wear: error: ") and "Traceback" not in err, err


def test_the_update_time_estimate_grows_with_the_revolutions_per_update():
    """revolutions_per_update = 1000 was announced as ~0.1 s an update; the estimate is the engine's for the
    update's 1 + N revolutions, so it grows with N (a factor (1 + 1000) / (1 + 4) here)."""
    from weftsim.wear.extrapolate import update_time

    short = update_time(weftsim.load_scene("reference"))
    long = update_time(weftsim.load_scene("reference", {"joint_e.wear.revolutions_per_update": 1000}))
    assert long / short == pytest.approx(1001 / 5, rel=1e-12)
    assert long > 1.0
