"""Files weftsim reads back, damaged or crafted (issue 24): each refused with one line, never a traceback,
an allocation of what a header claims, or a result that silently differs from what was saved."""

import io
import json
import os
import struct
import zipfile

import numpy as np
import pytest

import weftsim
from weftsim.post.results import JOINT_F_CHANNELS

FORMAT = "weftsim-result/1"


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """A short successful run of the reference engine, saved; returns (path, arrays, meta)."""
    result = weftsim.simulate(weftsim.load_scene("reference", revolutions=0.3), "reference")
    path = weftsim.save_result(result, tmp_path_factory.mktemp("base") / "base.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    return path, arrays, json.loads(str(arrays["meta"][()]))


def _npz(path, arrays):
    with open(path, "wb") as handle:
        np.savez_compressed(handle, **arrays)
    return path


def _refused(path, *words):
    """load_result refuses ``path`` with an OutputError of one line holding ``words``."""
    with pytest.raises(weftsim.OutputError) as caught:
        weftsim.load_result(path)
    text = str(caught.value)
    assert "\n" not in text and str(path) in text, text
    for word in words:
        assert word in text, text
    return text


def _npy(shape, dtype="<f8", body=b""):
    """Bytes of a .npy file whose header claims ``shape`` of ``dtype``, followed by ``body``."""
    header = "{'descr': '%s', 'fortran_order': False, 'shape': %r, }" % (dtype, tuple(shape))
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + body


def _members(arrays):
    out = {}
    for name, value in arrays.items():
        buffer = io.BytesIO()
        np.save(buffer, value)
        out[f"{name}.npy"] = buffer.getvalue()
    return out


def _zip(path, members, method=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", method) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return path


def _with_meta(arrays, meta):
    return {**arrays, "meta": np.array(json.dumps(meta))}


def test_saved_result_still_loads_equal(saved):
    path, arrays, meta = saved
    loaded = weftsim.load_result(path)
    assert loaded.status == "success" and loaded.scene.drive.revolutions == 0.3
    assert np.array_equal(loaded.steps["contact_force_N"], arrays["steps/contact_force_N"])


# --- the file itself -------------------------------------------------------------------------------------


def test_zero_byte_file(tmp_path):
    (tmp_path / "r.npz").write_bytes(b"")
    _refused(tmp_path / "r.npz", "empty (0 bytes")


def test_plain_npy_is_named(tmp_path):
    np.save(tmp_path / "r.npy", np.arange(5.0))
    _refused(tmp_path / "r.npy", "single NumPy array (.npy)")


def test_directory_and_garbage_and_truncations(tmp_path, saved):
    (tmp_path / "d.npz").mkdir()
    _refused(tmp_path / "d.npz", "is a directory")
    (tmp_path / "g.npz").write_bytes(os.urandom(2000))
    _refused(tmp_path / "g.npz", "not an NPZ (ZIP) archive")
    raw = saved[0].read_bytes()
    for cut in (100, len(raw) // 2, len(raw) - 10):
        (tmp_path / "t.npz").write_bytes(raw[:cut])
        _refused(tmp_path / "t.npz", "cannot be read as a weftsim result")
    damaged = bytearray(raw)
    damaged[len(raw) // 2: len(raw) // 2 + 64] = bytes(64)
    (tmp_path / "c.npz").write_bytes(bytes(damaged))
    _refused(tmp_path / "c.npz", "cannot be read as a weftsim result")


# --- sizes from the headers, before any allocation -----------------------------------------------------


def test_header_claiming_1e12_elements_is_refused_from_the_header(tmp_path, saved):
    members = _members(saved[1])
    members["samples/time_s.npy"] = _npy((10**12,))
    _refused(_zip(tmp_path / "h.npz", members), "claims shape (1000000000000,)", "8 TB")
    members = _members(saved[1])
    members["meta.npy"] = _npy((), "<U100000000")
    _refused(_zip(tmp_path / "m.npz", members), "'meta' claims shape ()")


def test_zip_bomb_is_refused_before_it_is_inflated(tmp_path, saved):
    """A ~1 MB file whose one member inflates to 1 GiB (the issue's was 4.3 MB to 4 GiB; the check reads only
    the ZIP directory, so the size does not matter, and 1 GiB of zeros compresses in a few seconds)."""
    members = _members(saved[1])
    del members["samples/time_s.npy"]
    path = tmp_path / "bomb.npz"
    size = 1 << 30
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
        with archive.open("samples/time_s.npy", "w", force_zip64=True) as member:
            member.write(_npy((size // 8,)))
            zeros = bytes(1 << 24)
            for _ in range(size // len(zeros)):
                member.write(zeros)
    assert path.stat().st_size < 4 * 2**20
    _refused(path, "ZIP bomb", "nothing was read")


# --- channels --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("change, words", [
    (lambda a: a.update({"samples/time_s": a["samples/time_s"][:-3]}), ["differ in length", "time_s has"]),
    (lambda a: a.update({"steps/contact_force_N": a["steps/contact_force_N"][:5]}), ["'steps' differ in length"]),
    (lambda a: a.update({"samples/contact_force_N": np.stack([a["samples/contact_force_N"]] * 2)}), ["is 1-D"]),
    (lambda a: a.update({"samples/contact_force_N": a["samples/contact_force_N"].astype(str)}), ["real numbers"]),
    (lambda a: a.update({"samples/contact_force_N": a["samples/contact_force_N"].astype(complex)}), ["real numbers"]),
    (lambda a: a.update({"samples/contact_force_N": np.array(5.0)}), ["is 1-D"]),
    (lambda a: a.pop("steps/penetration_m"), ["lacks channel(s) penetration_m"]),
    (lambda a: a.update({"samples/extra": np.zeros(3)}), ["'samples/extra.npy', which weftsim does not write"]),
    (lambda a: a.pop("meta"), ["no 'meta'"]),
    (lambda a: a.update({"steps/time_s": a["steps/time_s"][::-1].copy()}), ["not a time axis"]),
])
def test_damaged_channels(tmp_path, saved, change, words):
    arrays = dict(saved[1])
    change(arrays)
    _refused(_npz(tmp_path / "r.npz", arrays), *words)


def test_joint_f_channels_on_a_scene_without_f(tmp_path, saved):
    arrays = dict(saved[1])
    for table in ("samples", "steps"):
        for name in JOINT_F_CHANNELS:
            arrays[f"{table}/{name}"] = np.zeros_like(arrays[f"{table}/time_s"])
    _refused(_npz(tmp_path / "r.npz", arrays), "joint F's channels but its scene has F ideal")


# --- meta ------------------------------------------------------------------------------------------------


def _edit_scene(edit):
    def change(meta):
        edit(meta["scene"])
    return change


@pytest.mark.parametrize("change, words", [
    (lambda m: m.pop("scene"), ["'meta' lacks scene"]),
    (lambda m: m.pop("status"), ["'meta' lacks status"]),
    (lambda m: m.pop("engine"), ["'meta' lacks engine"]),
    (lambda m: m.update(engine="foo"), ["engine must be one of reference, exudyn, got 'foo'"]),
    (lambda m: m.update(status="ok"), ["status must be one of success, failed"]),
    (lambda m: m.update(message=7), ["'message' must be a string"]),
    (lambda m: m.update(events={"first_contact_time_s": "x"}), ["first_contact_time_s must be a time"]),
    (lambda m: m.update(scene={}), ["scene lacks field(s) name, geometry"]),
    (lambda m: m.update(scene=[1, 2]), ["'scene' must be a JSON object"]),
    (_edit_scene(lambda s: s.update(joint=5)), ["scene.joint must be a JSON object"]),
    (_edit_scene(lambda s: s["joint"].update(clearance=-1)), ["`clearance` must be >= 0"]),
    (_edit_scene(lambda s: s["joint"].update(clearance="abc")), ["scene.joint.clearance must be a number"]),
    (_edit_scene(lambda s: s["joint"].update(law="nope")), ["joint_e.law' must be one of"]),
    (_edit_scene(lambda s: s["drive"].update(speed=0)), ["drive.speed_rpm' must be >= 1"]),
    (_edit_scene(lambda s: s.update(bogus=1)), ["unknown field(s) bogus"]),
    (_edit_scene(lambda s: s["joint"].update(bearing_wear=[1e-3] * 7)), ["wear profiles"]),
    (_edit_scene(lambda s: s["geometry"].update(fourbar_branch=7)), ["fourbar_branch must be 1 or -1"]),
    (_edit_scene(lambda s: s["inertia"].update(coupler_inertia=[1, 2])), ["list of 3 numbers"]),
    # A changed length of the run: the data no longer belong to the scene.
    (_edit_scene(lambda s: s["drive"].update(revolutions=5.0)), ["steps end at", "not at the scene's end time"]),
])
def test_crafted_meta(tmp_path, saved, change, words):
    meta = json.loads(json.dumps(saved[2]))
    change(meta)
    _refused(_npz(tmp_path / "r.npz", _with_meta(saved[1], meta)), *words)


def test_meta_that_is_not_weftsim_json(tmp_path, saved):
    _refused(_npz(tmp_path / "a.npz", {**saved[1], "meta": np.array("{not json")}), "'meta' is not JSON")
    _refused(_npz(tmp_path / "b.npz", {**saved[1], "meta": np.arange(3.0)}), "not the one JSON text")
    deep = "[" * 100000 + "]" * 100000
    _refused(_npz(tmp_path / "c.npz", {**saved[1], "meta": np.array(deep)}), "nests too deeply")
    _refused(_npz(tmp_path / "d.npz", _with_meta(saved[1], [1, 2])), f"not a weftsim result of format {FORMAT}")


# --- the Python interface's other arguments ------------------------------------------------------------------


def test_save_result_of_something_else_and_a_bad_progress(tmp_path, saved):
    with pytest.raises(weftsim.ArgumentError, match="save_result: result must be a RunResult"):
        weftsim.save_result({"status": "success"}, tmp_path / "x.npz")
    (tmp_path / "dir.npz").mkdir()
    with pytest.raises(weftsim.OutputError, match="cannot write"):
        weftsim.save_result(weftsim.load_result(saved[0]), tmp_path / "dir.npz")
    with pytest.raises(weftsim.ArgumentError, match="progress must be None or a function"):
        weftsim.simulate("reference", "reference", progress=5)
    with pytest.raises(weftsim.ArgumentError, match="load_result: path must be a file path"):
        weftsim.load_result(None)
    with pytest.raises(weftsim.ArgumentError, match="load_sweep: directory must be a path"):
        weftsim.load_sweep(None)
    with pytest.raises(weftsim.OutputError, match="no such path"):
        weftsim.load_result("a\x00b.npz")
    with pytest.raises(weftsim.OutputError, match="cannot write"):
        weftsim.save_result(weftsim.load_result(saved[0]), "a\x00b.npz")


# --- a further round: special files, other keys ----------------------------------------------------------


def test_special_files_are_refused_without_blocking(tmp_path):
    """A named pipe blocked the reader forever (it waited for a writer); a device or a link loop are no results."""
    os.mkfifo(tmp_path / "pipe.npz")
    _refused(tmp_path / "pipe.npz", "not a regular file")
    (tmp_path / "loop.npz").symlink_to(tmp_path / "loop.npz")
    _refused(tmp_path / "loop.npz", "cannot be read as a weftsim result")
    with pytest.raises(weftsim.OutputError, match="not a regular file"):
        weftsim.load_result("/dev/zero")


def test_a_first_contact_after_the_end_of_the_run(tmp_path, saved):
    meta = json.loads(json.dumps(saved[2]))
    meta["events"]["first_contact_time_s"] = 10.0
    _refused(_npz(tmp_path / "r.npz", _with_meta(saved[1], meta)), "after the run's end")


def test_a_manifest_that_is_a_directory_is_one_line(tmp_path, capsys):
    from weftsim.cli.commands import main

    (tmp_path / "out" / ".weftsim-output.json").mkdir(parents=True)
    assert main(["run", "reference", "--engine", "reference", "--revolutions", "0.05", "--no-plot",
                 "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is not weftsim's manifest file" in err[0], err


def test_a_manifest_listing_odd_names_removes_nothing_of_the_user(tmp_path):
    """A run manifest edited to list a directory, a parent path and non-text entries: the rerun neither fails
    nor removes anything but its own stale files."""
    from weftsim.post.output import MANIFEST, write_files, write_text

    out = tmp_path / "out"
    (out / "sub").mkdir(parents=True)
    (tmp_path / "x").write_text("keep")
    (out / MANIFEST).write_text(json.dumps({"files": ["../x", "sub", 5, None, "old.csv"], "state": "complete"}))
    (out / "old.csv").write_text("stale")
    write_files(out, {"kind": "test"}, {"a": ("a.txt", lambda p: write_text(p, "new"))})
    assert (out / "sub").is_dir() and (tmp_path / "x").read_text() == "keep"
    assert not (out / "old.csv").exists() and (out / "a.txt").read_text() == "new"
