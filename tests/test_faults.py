"""Faults during a run (issue 16, single runs): a run that ends early keeps what it computed and
says where; nothing is lost, no traceback, no hang.

- Ctrl-C (SIGINT) during ``weftsim run``: the partial results are written, marked incomplete,
  exit 130 with one line saying where.  A long run shows its estimated run time first.
- A full disk during ``run`` or ``kinematics``: the files that fit are written, the others kept in
  a rescue directory, the manifest says "incomplete" (never left "writing"), exit 3 with one line.
  Tested on a real tmpfs of a few hundred kB where the machine lets the test mount one (in a
  private mount namespace), and everywhere with writes that raise ENOSPC.
- ``| head``: no BrokenPipeError.
- Files get the user's umask.
- ``compare`` exit 3 and 4 say why in one line on stderr; ``--json`` prints only JSON on stdout.
"""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from weftsim.cli import commands as cli
from weftsim.post import output
from weftsim.errors import EXIT_DISAGREE, EXIT_FAILED
from weftsim.post.output import MANIFEST
from weftsim.input.scene import load_scene
from weftsim.post.results import scene_channels

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "models" / "reference.toml"
IDEAL = ROOT / "models" / "ideal.toml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}  # the package of this tree, whatever the working directory


def popen(*args, cwd=None, env=None, **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "weftsim.cli", *map(str, args)], cwd=cwd, env=env or ENV,
                            text=True, **kwargs)  # fmt: skip


def run_cli(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "weftsim.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env or ENV, timeout=300)  # fmt: skip


def _header(csv: Path) -> list[str]:
    """The column names of a CSV file weftsim wrote."""
    return csv.read_text().split("\n", 1)[0].split(",")


def error_line(stderr: str) -> str:
    """The last line of stderr, which must be the one error line (no traceback anywhere)."""
    assert "Traceback" not in stderr, stderr
    return stderr.strip().splitlines()[-1]


# --- Ctrl-C ---------------------------------------------------------------------------------


@pytest.mark.parametrize("engine, signum, words", [
    ("reference", signal.SIGINT, "stopped by Ctrl-C, SIGINT at t = "),
    ("exudyn", signal.SIGINT, "stopped by Ctrl-C, SIGINT at t = "),
    ("reference", signal.SIGTERM, "stopped by SIGTERM at t = "),
])  # fmt: skip
def test_a_stopped_run_keeps_its_partial_results_and_says_where(tmp_path, engine, signum, words):
    """1000 revolutions (hours): the estimate comes first, then the signal after the first progress
    line; the run stops at its next step, writes what it computed and exits 128 + the signal.

    Independent of the machine's speed: the signal may arrive before the first revolution is done (a loaded
    2-core machine: one output row), and no wall-clock bound is asserted (a guard kills a hung child after
    10 min; the stop is checked by where the run ended, far before its 1000 revolutions)."""
    out = tmp_path / "run"
    # The automatic paths do 1000 revolutions in minutes: scipy's DOP853 and the rigid-body model take hours.
    slow = {"reference": '[solver.reference]\nmethod = "DOP853"\nrtol = 1e-9\natol = 1e-12\n',
            "exudyn": '[solver.exudyn]\nmodel = "rigid_body"\n'}[engine]
    scene = tmp_path / "slow.toml"
    scene.write_text(f'extends = "{REFERENCE.as_posix()}"\nname = "slow"\n{slow}')
    child = popen("run", scene, "--engine", engine, "--revolutions", 1000, "--no-plot", "-o", out,
                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)  # fmt: skip
    lines = []
    guard = threading.Timer(600.0, child.kill)  # a hang guard only, never a speed limit
    guard.start()
    try:
        while True:
            line = child.stderr.readline()
            assert line, f"the run ended before a progress line: {''.join(lines)}"
            lines.append(line)
            # A progress line past 0.0 %, so some time is simulated: the first line comes after 2 s of wall
            # time, and on a loaded machine (the suite's parallel run at load 7) it read 0.0 % before the
            # first step, and the stop kept only t = 0.
            shown = re.search(r"([0-9.]+)%\s+elapsed", line)
            if shown and float(shown[1]) > 0.0:
                break
        child.send_signal(signum)
        rest = child.communicate()[1]
    finally:
        guard.cancel()
        if child.poll() is None:
            child.kill()
    assert child.returncode == 128 + signum, rest  # 130 for Ctrl-C, as a shell reports it
    # The estimate is the first line, a warning (hours, far above progress.LONG_RUN_S).
    assert "warning: estimated run time" in lines[0] and "1000 revolutions" in lines[0], lines
    last = error_line(rest)
    assert last.startswith("weftsim run: error: " + words) and str(out) in last, last
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False and "stopped by the user" in summary["message"]
    assert summary["solver"].get("failure", "interrupted") == "interrupted"
    assert json.loads((out / MANIFEST).read_text())["state"] == "complete"  # every file written
    channels = np.loadtxt(out / "channels.csv", delimiter=",", skiprows=1, ndmin=2)  # one row if stopped early
    # Every channel of the scene (the loose joint E's load among them), from the start to where the run
    # stopped, on the output grid.
    assert _header(out / "channels.csv") == list(scene_channels(load_scene(scene)))
    assert channels[0, 0] == 0.0 and channels.shape[1] == len(scene_channels(load_scene(scene)))
    assert 0.0 < summary["simulated_time_s"] < 1000 * 60 / 400
    assert channels[-1, 0] <= summary["simulated_time_s"] + 1e-12
    assert summary["simulated_time_s"] - channels[-1, 0] < 0.5 / 360 * 60 / 400 + 1e-12  # within one sample


# --- A full disk ----------------------------------------------------------------------------


def _can_mount_tmpfs() -> str | None:
    """Why a private tmpfs cannot be mounted here, or None when it can."""
    if shutil.which("unshare") is None or shutil.which("mount") is None:
        return "no unshare/mount command"
    probe = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c",
                            "mount -t tmpfs -o size=64k tmpfs /mnt 2>/dev/null || mount -t tmpfs -o size=64k tmpfs "
                            "\"$TMPDIR\""], capture_output=True, text=True, env={**os.environ, "TMPDIR": "/tmp"})
    if probe.returncode != 0:
        return f"cannot mount a tmpfs in a private mount namespace: {probe.stderr.strip()}"
    return None


# Bytes of the small tmpfs: the reference scene's channels.csv over 0.3 revolutions at 0.5 deg
# (217 rows, ~50 kB) and its summary.json (~6 kB) fit, its result.npz (~150 kB: 1058 solver steps),
# channels.png (~150 kB) and orbit.png do not.
TMPFS_BYTES = 96 * 1024


def test_disk_full_on_a_real_tmpfs_keeps_what_was_computed(tmp_path):
    why = _can_mount_tmpfs()
    if why:
        pytest.skip(why)
    disk, rescue, copy = tmp_path / "disk", tmp_path / "rescue", tmp_path / "copy"
    for d in (disk, rescue):
        d.mkdir()
    # In a private mount namespace the tmpfs vanishes with the command: the script copies what the
    # run left on it (and its exit status and stderr) to the test's directory first.
    script = (f'mount -t tmpfs -o size={TMPFS_BYTES} tmpfs "{disk}" && cd "{tmp_path}" && '
              f'"{sys.executable}" -m weftsim.cli run "{REFERENCE}" --engine reference --revolutions 0.3 '
              f'-o "{disk}/run" 2> stderr.txt; echo $? > rc.txt; cp -a "{disk}/run" "{copy}"')
    done = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c", script],
                          capture_output=True, text=True, env={**ENV, "TMPDIR": str(rescue)}, timeout=300)
    assert done.returncode == 0, done.stderr
    assert int((tmp_path / "rc.txt").read_text()) == EXIT_FAILED
    last = error_line((tmp_path / "stderr.txt").read_text())
    assert "cannot write channels.png, orbit.png, result.npz" in last and "No space left on device" in last, last
    assert "channels.csv, scene.toml, summary.json written there" in last and "kept in" in last, last
    manifest = json.loads((copy / MANIFEST).read_text())
    assert manifest["state"] == "incomplete" and manifest["files"] == ["channels.csv", "scene.toml", "summary.json"]
    assert manifest["missing"] == {"channels.png": "No space left on device", "orbit.png": "No space left on device",
                                   "result.npz": "No space left on device"}
    (kept,) = rescue.glob("weftsim-rescue-*/channels.png")
    assert (kept.parent / "orbit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert kept.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # a complete figure, where the line says
    assert str(kept.parent) in last and manifest["rescued_to"] == str(kept.parent)
    assert json.loads((copy / "summary.json").read_text())["complete"] is True  # the run itself succeeded
    # The rescued result is the whole run: its output samples are the rows of the channels.csv that fitted.
    import weftsim

    rescued = weftsim.load_result(kept.parent / "result.npz")
    assert rescued.samples["time_s"].size == np.loadtxt(copy / "channels.csv", delimiter=",", skiprows=1).shape[0]


class FullDisk:
    """Every write into ``directory`` after the first ``allowed`` ones raises ENOSPC, as a disk
    that filled up during the run would (the files are written through output.write_atomic)."""

    def __init__(self, monkeypatch, directory: Path, allowed: int = 1):
        self.directory, self.allowed, self.real = Path(directory), allowed, output.write_atomic
        monkeypatch.setattr(output, "write_atomic", self)

    def __call__(self, target, write):
        if Path(target).parent == self.directory:
            if self.allowed <= 0:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            self.allowed -= 1
        return self.real(target, write)


@pytest.mark.parametrize("command, files", [
    ("run", ["channels.csv", "channels.png", "orbit.png", "result.npz", "scene.toml", "summary.json"]),
    ("kinematics", ["kinematics.csv", "kinematics.png", "scene.toml"]),
])  # fmt: skip
def test_disk_full_rescues_every_file_and_marks_the_manifest(tmp_path, monkeypatch, capsys, command, files):
    """The disk is full right after the manifest was opened: not even the manifest's last update
    can be written as a new file.  Every file goes to the rescue directory, complete, and the
    manifest is updated in the room it reserved."""
    out, rescue = tmp_path / "out", tmp_path / "rescue"
    rescue.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(rescue))
    FullDisk(monkeypatch, out, allowed=1)  # the manifest "writing"; nothing after it
    argv = [command, str(REFERENCE), "-o", str(out)] + (["--engine", "reference", "--revolutions", "0.05"]
                                                        if command == "run" else [])  # fmt: skip
    status = cli.main(argv)
    err = capsys.readouterr().err
    assert status == EXIT_FAILED
    last = error_line(err)
    assert f"cannot write {', '.join(files)} to {out}: No space left on device" in last, last
    assert "manifest state 'incomplete'" in last and "kept in" in last, last
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["state"] == "incomplete" and manifest["files"] == []
    assert sorted(manifest["missing"]) == files
    (kept,) = rescue.glob("weftsim-rescue-*")
    assert sorted(p.name for p in kept.iterdir()) == files
    table = files[0]
    data = np.loadtxt(kept / table, delimiter=",", skiprows=1)
    if command == "run":  # all of the run's samples: 0.05 revolutions on the 0.5 deg grid, every scene channel
        assert _header(kept / table) == list(scene_channels(load_scene(REFERENCE)))
        assert data.shape == (37, len(scene_channels(load_scene(REFERENCE)))) and data[-1, 1] == pytest.approx(18.0)
        assert json.loads((kept / "summary.json").read_text())["complete"] is True
    else:  # one revolution on the 0.5 deg grid
        assert data.shape[0] == 721 and data[-1, 0] == pytest.approx(360.0)


def test_disk_full_with_no_rescue_says_the_files_could_not_be_kept(tmp_path, monkeypatch, capsys):
    """Nowhere to put them (the temporary directory is full too): the line says which files are
    lost and why, and the manifest still leaves "writing"."""
    out, rescue = tmp_path / "out", tmp_path / "rescue"
    rescue.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(rescue))
    FullDisk(monkeypatch, out, allowed=1)
    real = output.write_csv

    def full_everywhere(target, columns):
        if Path(target).parent != out:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(target, columns)

    monkeypatch.setattr(output, "write_csv", full_everywhere)
    status = cli.main(["run", str(REFERENCE), "-o", str(out), "--engine", "reference", "--revolutions", "0.05",
                       "--no-plot"])  # fmt: skip
    last = error_line(capsys.readouterr().err)
    assert status == EXIT_FAILED
    assert "channels.csv could not be kept anywhere (No space left on device): free space and rerun" in last, last
    assert "summary.json kept in" in last, last
    assert json.loads((out / MANIFEST).read_text())["state"] == "incomplete"


def test_manifest_update_in_place_fits_in_its_reserved_room(tmp_path):
    output.begin_directory(tmp_path, {"kind": "run"})
    size = (tmp_path / MANIFEST).stat().st_size
    assert size == output.MANIFEST_RESERVE
    output._overwrite_in_place(tmp_path / MANIFEST, output.to_json({"kind": "run", "state": "incomplete"}))
    assert (tmp_path / MANIFEST).stat().st_size == size  # no new block needed
    assert json.loads((tmp_path / MANIFEST).read_text())["state"] == "incomplete"


# --- A closed pipe, file modes ----------------------------------------------------------------


def test_output_piped_into_head_ends_quietly(tmp_path):
    """``weftsim kinematics ... | head -1``: head closes the pipe after one line."""
    child = popen("kinematics", REFERENCE, "-o", tmp_path / "k", stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = child.stdout.readline()
    child.stdout.close()  # as head does after its line
    err = child.stderr.read()
    child.wait(timeout=120)
    assert first.startswith("scene reference:")
    assert "Traceback" not in err and "BrokenPipe" not in err, err
    assert child.returncode in (0, cli.EXIT_BROKEN_PIPE)  # 0 if all of stdout fit in the pipe's buffer first
    assert json.loads((tmp_path / "k" / MANIFEST).read_text())["state"] == "complete"


def test_closed_stdout_gives_the_sigpipe_status(tmp_path):
    """stdout already closed by the reader: the first print fails; exit 141, nothing on stderr."""
    script = ("import os, sys\nr, w = os.pipe()\nos.close(r)\nos.dup2(w, 1)\n"
              "from weftsim.cli.commands import main\nsys.exit(main(sys.argv[1:]))\n")
    done = subprocess.run([sys.executable, "-c", script, "kinematics", str(REFERENCE), "-o", str(tmp_path / "k")],
                          capture_output=True, text=True, env=ENV, timeout=120)  # fmt: skip
    assert done.returncode == cli.EXIT_BROKEN_PIPE, done.stderr
    assert done.stderr == ""
    assert (tmp_path / "k" / "kinematics.csv").exists()  # written before the report


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_files_get_the_users_umask(tmp_path, umask, mode):
    done = subprocess.run([sys.executable, "-m", "weftsim.cli", "kinematics", str(REFERENCE), "-o",
                           str(tmp_path / "k")], capture_output=True, text=True, env=ENV, timeout=120,
                          preexec_fn=lambda: os.umask(umask))  # fmt: skip
    assert done.returncode == 0, done.stderr
    for name in ("kinematics.csv", "kinematics.png", MANIFEST):
        assert stat.S_IMODE((tmp_path / "k" / name).stat().st_mode) == mode, name


# --- compare: the reason on stderr, only JSON on stdout -----------------------------------------


def _scene(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(f'extends = "{IDEAL.as_posix()}"\n[drive]\nrevolutions = 0.05\n' + text)
    return path


def test_compare_disagreement_says_why_on_stderr_and_json_stays_clean(tmp_path):
    # A tolerance no two engines meet (their ideal-joint curves differ by ~1e-6 of the peak).
    scene = _scene(tmp_path, "[compare]\nideal_curves = 1e-15\n")
    env = {**ENV, "EXUDYN_SUPPRESS_UI_WINDOW_OPEN": "1"}  # Exudyn then prints a note on import
    done = run_cli("compare", scene, "--json", "-o", tmp_path / "cmp", env=env)
    assert done.returncode == EXIT_DISAGREE
    report = json.loads(done.stdout)  # stdout is one JSON object and nothing else
    assert report["agree"] is False
    last = error_line(done.stderr)
    assert last.startswith("weftsim compare: error: engines disagree on 2 of 2 checks; first: "), last
    assert "above tolerance 1e-15" in last and str(tmp_path / "cmp" / "compare.json") in last
    assert "EXUDYN_SUPPRESS_UI_WINDOW_OPEN" in done.stderr  # the library's note went to stderr


def test_compare_with_a_failed_engine_says_which_and_why(tmp_path):
    # Exudyn needs ~1500 steps here, the closed-form reference none: only Exudyn fails.
    scene = _scene(tmp_path, "[limits]\nmax_steps = 5\n")
    done = run_cli("compare", scene, "-o", tmp_path / "cmp")
    assert done.returncode == EXIT_FAILED
    last = error_line(done.stderr)
    assert last.startswith("weftsim compare: error: engine exudyn failed: Exudyn engine failed at t = "), last
    assert "limits.max_steps" in last and f"{tmp_path / 'cmp'}/exudyn" in last, last
    assert "engines not compared: an engine failed" in done.stdout  # the table is still printed


def test_progress_on_a_closed_stream_does_not_end_the_run():
    """stderr piped into a reader that exited (``2>&1 | head -1``): progress stops, the run goes on."""
    from weftsim.checks.progress import Progress

    read, write = os.pipe()
    os.close(read)
    stream = os.fdopen(write, "w")
    progress = Progress("run", stream=stream, delay=0.0, interval=0.0)
    progress(0.5)  # raises BrokenPipeError inside; swallowed
    progress(0.9)
    progress.close()
    assert progress.stream is None


def test_a_run_whose_steps_outgrow_the_memory_stops_and_keeps_them(monkeypatch):
    """A run that records more steps than half the free memory holds (the loom's worn E and F wear update: 12
    million rows, a MemoryError at 2.24 GiB) stops with one line naming the key that shortens it, its rows kept;
    a wear update that fails so is not retried at a tighter tolerance (more steps).  The free memory is made
    small here: budget 200 rows, reached within the first 1 % of a 0.2-revolution run (~1,700 rows), and by the wear update's whole run."""
    import weftsim
    from weftsim.checks import guards
    from weftsim.post import npz_guard
    from weftsim.wear.extrapolate import UpdateFailed, simulate_update

    monkeypatch.setattr(npz_guard, "available_memory", lambda: 2 * 200 * guards.ROW_BYTES)
    scene = load_scene("reference", overrides={"drive.revolutions": 0.2})
    result = weftsim.simulate(scene, "reference", progress=lambda fraction: None, on_warning=lambda text: None)
    assert result.status == "failed" and result.solver_stats["failure"] == "memory"
    assert "solver steps" in result.message and "wear.revolutions_per_update" in result.message
    assert "\n" not in result.message
    t = result.steps["time_s"]
    assert 0.0 < t[-1] < scene.drive.end_time and t.size >= 200
    wearing = load_scene("reference")
    calls = []
    real = weftsim.engines.simulate
    monkeypatch.setattr(weftsim.engines, "simulate", lambda *a, **k: calls.append(a) or real(*a, **k))
    bearing = journal = np.zeros(wearing.joint.wear.profile_points)
    with pytest.raises(UpdateFailed, match="solver steps"):
        simulate_update(wearing, bearing, journal)
    assert len(calls) == 1
