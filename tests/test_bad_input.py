"""Bad input (issue 7, part 3) through the real command line: every malformed scene, flag or output
directory gets one clear line on stderr and exit status 2, before anything is simulated or written.
Output files are atomic (a run killed with SIGKILL in the middle of writing leaves the previous
complete files) and an output directory is never silently mixed with another run's files.

The command lines of the table run once per module, in this process through ``weftsim.cli.main`` (the console
script's own function: what it prints on stderr and the status it returns, or the SystemExit of the parser), each
in its test directory; the few that hand weftsim a FIFO or a device run as separate processes, so that a
regression that blocks on reading them ends at the subprocess's timeout instead of hanging the suite (the table
as ~100 processes of ~0.5 s each cost ~55 s of subprocesses; in process it takes a few seconds).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import subprocess
import sys
import time
import traceback
from pathlib import Path

import pytest

from weftsim.post.output import MANIFEST

from weftsim.cli.commands import EXIT_USAGE

MODELS = Path(__file__).resolve().parents[1] / "models"
REFERENCE = MODELS / "reference.toml"
EXTENDS = f'extends = "{REFERENCE.as_posix()}"\n'


def cli(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "weftsim.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)  # fmt: skip


def cli_in_process(*args, cwd: Path) -> subprocess.CompletedProcess:
    """What ``weftsim ARGS`` run in ``cwd`` prints and returns, from ``weftsim.cli.main`` in this process: its
    status (or the parser's SystemExit code), stdout and stderr; an exception that escapes main() is the
    traceback the console script would print, with status 1."""
    from weftsim.cli.commands import main

    out, err, here = io.StringIO(), io.StringIO(), os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = main([str(a) for a in args])
            except SystemExit as exc:
                status = exc.code if isinstance(exc.code, int) else 1
            except Exception:  # noqa: BLE001 - what an uncaught exception shows the user
                traceback.print_exc(file=sys.stderr)
                status = 1
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(["weftsim", *map(str, args)], status, out.getvalue(), err.getvalue())


# Rows that hand weftsim a FIFO or a device: in their own process (a read would block; the timeout ends it).
BLOCKING = {"scene:extends-a-fifo", "scene:extends-dev-zero", "flag:scene-is-a-fifo", "flag:scene-is-dev-zero"}


def _without(key_line: str) -> str:
    """The reference scene (no extends) with one line removed."""
    lines = REFERENCE.read_text().splitlines()
    kept = [line for line in lines if not line.startswith(key_line)]
    assert len(kept) == len(lines) - 1, key_line
    return "\n".join(kept) + "\n"


# Scene files: (id, file text, words the one-line message must hold).  "{dir}" is the test directory.
SCENES = [
    ("missing-keys-top-level", '[drive]\nspeed_rpm = 400.0\n',
     ["missing required keys", "mechanism.l_oe_mm", "joint_e.clearance_mm", "drive.revolutions", "extends"]),
    ("missing-one-key", _without("clearance_mm"), ["missing required keys joint_e.clearance_mm;"]),
    ("empty-file", "", ["missing required keys", "inertia.rod_mass_kg"]),
    ("unknown-key", EXTENDS + "[joint_e]\nclearence_mm = 0.1\n",
     ["unknown key 'joint_e.clearence_mm'", "joint_e.clearance_mm"]),
    ("unknown-section", EXTENDS + "[limit]\nmax_steps = 10\n", ["unknown key 'limit.max_steps'", "limits"]),
    ("unknown-top-level-key", EXTENDS + 'nmae = "x"\n', ["unknown key 'nmae'"]),
    ("misspelt-key-in-partial-scene", '[joint_e]\nclearence_mm = 0.1\n', ["unknown key 'joint_e.clearence_mm'"]),
    ("string-for-number", EXTENDS + '[drive]\nspeed_rpm = "fast"\n', ["drive.speed_rpm", "'fast'", "number"]),
    ("bool-for-number", EXTENDS + "[drive]\nspeed_rpm = true\n", ["drive.speed_rpm", "True", "number"]),
    ("list-for-number", EXTENDS + "[joint_e]\nclearance_mm = [0.1]\n", ["joint_e.clearance_mm", "number"]),
    ("table-for-number", EXTENDS + "[joint_e.clearance_mm]\nvalue = 0.1\n",
     ["unknown key 'joint_e.clearance_mm.value'"]),
    ("float-for-int", EXTENDS + "[limits]\nmax_steps = 10.5\n", ["limits.max_steps", "whole number"]),
    ("number-for-string", EXTENDS + "[joint_e]\nlaw = 3\n", ["joint_e.law", "string"]),
    ("name-not-string", EXTENDS + "name = 3\n", ["key 'name' must be a string"]),
    ("nan", EXTENDS + "[drive]\nspeed_rpm = nan\n", ["drive.speed_rpm", "nan", "finite"]),
    ("inf", EXTENDS + "[joint_e]\nrestitution = inf\n", ["joint_e.restitution", "inf", "finite"]),
    ("overflows-in-si", EXTENDS + "[joint_e.bearing_material]\nyoungs_modulus_gpa = 1e300\n",
     ["youngs_modulus_gpa", "finite number (also in SI units)"]),
    ("integer-beyond-float", EXTENDS + "[drive]\nspeed_rpm = 1" + "0" * 400 + "\n", ["drive.speed_rpm", "finite"]),
    ("negative", EXTENDS + "[joint_e]\nclearance_mm = -0.1\n", ["joint_e.clearance_mm", "-0.1", ">= 0"]),
    ("zero-length", EXTENDS + "[mechanism]\nl_oe_mm = 0\n", ["mechanism.l_oe_mm", "> 0"]),
    ("zero-revolutions", EXTENDS + "[drive]\nrevolutions = 0\n", ["drive.revolutions", "> 0"]),
    ("zero-restitution", EXTENDS + "[joint_e]\nrestitution = 0.0\n", ["joint_e.restitution", "> 0"]),
    ("joint-f-keys-without-clearance", EXTENDS + "[joint_f]\nlaw = 'flores'\n",
     ["joint_f.law", "joint F is ideal", "joint_f.clearance_mm > 0"]),
    ("joint-f-negative", EXTENDS + "[joint_f]\nclearance_mm = -0.1\n", ["joint_f.clearance_mm", "-0.1", ">= 0"]),
    ("negative-budget", EXTENDS + "[limits]\nmax_wall_time_s = -1\n", ["limits.max_wall_time_s", ">= 0"]),
    ("penetration-bound-above-1", EXTENDS + "[limits]\nmax_penetration_ratio = 2\n",
     ["limits.max_penetration_ratio", "<= 1"]),
    ("zero-damping-ratio", EXTENDS + "[limits]\nmax_damping_ratio = 0\n", ["limits.max_damping_ratio", "> 0"]),
    ("negative-yield-strength", EXTENDS + "[joint_e.bearing_material]\nyield_strength_mpa = -250\n",
     ["joint_e.bearing_material.yield_strength_mpa", "-250", "> 0"]),
    ("string-yield-strength", EXTENDS + '[joint_e.journal_material]\nyield_strength_mpa = "mild"\n',
     ["joint_e.journal_material.yield_strength_mpa", "'mild'", "number"]),
    ("impossible-four-bar", EXTENDS + "[mechanism]\nl_ef_mm = 100\n", ["cannot be assembled", "crank angle"]),
    ("crank-inclination-90", EXTENDS + "[mechanism]\ncrank_inclination_deg = 90\n",
     ["mechanism.crank_inclination_deg", "< 90"]),
    ("clearance-beyond-journal", EXTENDS + "[joint_e]\nclearance_mm = 4\njournal_radius_mm = 3\n",
     ["joint_e.clearance_mm", "smaller than the journal radius"]),
    ("unknown-law", EXTENDS + '[joint_e]\nlaw = "hertz_magic"\n', ["joint_e.law", "hertz_magic", "variable_kd"]),
    ("friction-ramp-reversed", EXTENDS + "[joint_e]\nfriction_velocities_m_s = [2e-4, 1e-4]\n",
     ["friction_velocities_m_s", "v0 < v1"]),
    ("tape-shorter-than-its-stroke", EXTENDS + "[rapier_tape]\nlength_mm = 500\n",
     ["rapier_tape.length_mm", "at least free_length_mm + the stroke"]),
    ("tape-unknown-model", EXTENDS + '[rapier_tape]\nmodel = "elastic"\n', ["rapier_tape.model", "'elastic'", "'flexible'"]),
    ("tape-modes-not-whole", EXTENDS + "[rapier_tape]\nmodes = 4.5\n", ["rapier_tape.modes", "whole number"]),
    ("exchange-ideal-taker-of-a-tape", EXTENDS + '[rapier_tape]\nmodel = "flexible"\n[exchange]\ntaker_clearance_mm = 0\n',
     ["exchange.taker_clearance_mm", "ideal joints", "needs a clearance at E"]),
    ("duty-day-longer-than-24-h", EXTENDS + "[duty]\nhours_per_day = 25\n", ["duty.hours_per_day", "25", "<= 24"]),
    ("duty-negative-stops", EXTENDS + "[duty]\nstops_per_hour = -2\n", ["duty.stops_per_hour", "-2", ">= 0"]),
    ("unknown-method", EXTENDS + '[solver.reference]\nmethod = "Euler"\n', ["solver.reference.method", "'Euler'"]),
    ("unknown-callback", EXTENDS + '[solver.exudyn]\ncallback = "fortran"\n', ["solver.exudyn.callback", "'fortran'"]),
    ("extends-missing-file", 'extends = "nowhere.toml"\n', ["nowhere.toml", "not found"]),
    ("extends-not-a-path", "extends = 3\n", ["'extends' must be a path or the name of a bundled scene"]),
    ("extends-itself", 'extends = "scene.toml"\n', ["loops back"]),
    ("not-toml", "this is = = not toml\n", ["not valid TOML"]),
    ("duplicate-key", EXTENDS + "[drive]\nspeed_rpm = 400\nspeed_rpm = 500\n", ["not valid TOML"]),
    # Issue 16 (round two).  The same key as a quoted dotted key at the top level and in its table:
    # TOML sees two different keys, the scene one, given twice.
    ("duplicate-key-across-tables", EXTENDS + '"joint_e.clearance_mm" = 0.01\n[joint_e]\nclearance_mm = 0.25\n',
     ["key 'joint_e.clearance_mm' is given twice", '"joint_e.clearance_mm" at the top level',
      "clearance_mm in [joint_e]"]),
    ("duplicate-key-one-level-down", EXTENDS + '[joint_e]\n"journal_material.poisson_ratio" = 0.3\n'
     "[joint_e.journal_material]\npoisson_ratio = 0.29\n",
     ["given twice", '"journal_material.poisson_ratio" in [joint_e]', "poisson_ratio in [joint_e.journal_material]"]),
    # A newline and a terminal escape sequence (clear screen) in a key: escaped in the one line.
    ("newline-and-escape-in-key", EXTENDS + '[joint_e]\n"clear\\nance\\u001b[2J" = 1\n',
     ["unknown key 'joint_e.clear\\nance\\x1b[2J'"]),
    ("newline-in-name", EXTENDS + 'name = "two\\nlines"\n', ["key 'name'", "printable", "'two\\nlines'"]),
    ("escape-in-name", EXTENDS + 'name = "\\u001b[31mred"\n', ["key 'name'", "printable", "\\x1b[31mred"]),
    ("extends-a-fifo", 'extends = "fifo"\n', ["fifo", "not a regular file"]),
    ("extends-dev-zero", 'extends = "/dev/zero"\n', ["/dev/zero", "not a regular file"]),
    ("extends-chain-of-1500", 'extends = "chain/1499.toml"\n', ["'extends' chain is longer than 64 files"]),
    ("extends-a-huge-file", 'extends = "huge.toml"\n', ["huge.toml", "2097152 bytes", "more than a scene file's"]),
    ("sample-deg-1e-9", EXTENDS + "[output]\nsample_deg = 1e-9\n",
     ["output.sample_deg = 1e-09", "drive.revolutions = 2", "7.2e+11 output samples", "memory"]),
]
# Rows whose message names a file outside the test directory (the scene extends it).
NAMES_A_SYSTEM_FILE = {"extends-dev-zero"}


def make_hostile_files(directory: Path) -> None:
    """A FIFO (reading it would block until a writer comes), a 2 MiB file, and a chain of 1500
    scene files each extending the one before (the first extends the reference scene)."""
    os.mkfifo(directory / "fifo")
    (directory / "huge.toml").write_text(("# padding" + " " * 54 + "\n") * (1 << 15))  # 2 MiB of comments
    chain = directory / "chain"
    chain.mkdir()
    (chain / "0.toml").write_text(EXTENDS)
    for k in range(1, 1500):
        (chain / f"{k}.toml").write_text(f'extends = "{k - 1}.toml"\n')


HOSTILE_ROWS = {"extends-a-fifo", "extends-chain-of-1500", "extends-a-huge-file"}  # the rows that read them

# Command lines: (id, arguments after the program, words).  "{scene}" is the reference scene,
# "{dir}" the test directory.
FLAGS = [
    ("no-command", [], ["required"]),
    ("unknown-command", ["fly", "{scene}"], ["invalid choice", "'fly'"]),
    ("no-scene-argument", ["run"], ["required", "scene"]),
    ("unknown-flag", ["run", "{scene}", "--rpm", "400"], ["unrecognized arguments", "--rpm"]),
    ("scene-not-found", ["run", "{dir}/nope.toml"], ["nope.toml", "not found"]),
    ("scene-is-a-directory", ["run", "{dir}"], ["is a directory"]),
    ("scene-not-utf8", ["run", "{dir}/latin1.toml"], ["cannot be read"]),
    ("unknown-engine", ["run", "{scene}", "--engine", "adams", "-o", "{dir}/engine-out"], ["--engine", "adams"]),
    ("negative-speed", ["run", "{scene}", "--speed-rpm", "-5"], ["--speed-rpm", "> 0"]),
    ("nan-speed", ["run", "{scene}", "--speed-rpm", "nan"], ["--speed-rpm", "finite"]),
    ("inf-speed", ["run", "{scene}", "--speed-rpm", "inf"], ["--speed-rpm", "finite"]),
    ("word-speed", ["run", "{scene}", "--speed-rpm", "fast"], ["--speed-rpm", "number"]),
    ("speed-beyond-range", ["run", "{scene}", "--speed-rpm", "6000"], ["command line", "drive.speed_rpm", "<= 5000"]),
    ("zero-revolutions", ["run", "{scene}", "--revolutions", "0"], ["--revolutions", "> 0"]),
    ("negative-clearance", ["run", "{scene}", "--clearance-mm", "-1"], ["--clearance-mm", ">= 0"]),
    ("clearance-beyond-range", ["run", "{scene}", "--clearance-mm", "20"],
     ["command line", "joint_e.clearance_mm", "<= 5", "20"]),
    ("unknown-law-flag", ["run", "{scene}", "--law", "magic"], ["command line", "joint_e.law", "magic"]),
    ("output-uncreatable", ["run", "{scene}", "-o", "/proc/forbidden"], ["cannot create output directory"]),
    ("output-under-a-file", ["run", "{scene}", "-o", "{dir}/blocker/sub"], ["cannot create output directory"]),
    ("output-is-a-file", ["run", "{scene}", "-o", "{dir}/blocker"], ["exists and is not a directory"]),
    ("output-foreign-directory", ["run", "{scene}", "-o", "{dir}/thesis"],
     ["not written by weftsim", "--force"]),
    ("compare-foreign-directory", ["compare", "{scene}", "-o", "{dir}/thesis"], ["not written by weftsim"]),
    ("kinematics-bad-scene", ["kinematics", "{dir}/nan.toml"], ["drive.speed_rpm", "finite"]),
    ("sweep-bad-key", ["sweep", "{scene}", "--vary", "clearence_mm=0.1,0.2", "-o", "{dir}/sweep-out"],
     ["clearence_mm"]),
    # Issue 16 (round two).  No -o: the default output directory out/<name> must stay under out/.
    ("scene-is-a-fifo", ["run", "{dir}/fifo"], ["fifo", "not a regular file"]),
    ("scene-is-dev-zero", ["run", "/dev/zero"], ["/dev/zero", "not a regular file"]),
    ("name-climbs-out-of-out", ["run", "{dir}/climb.toml"],
     ["key 'name' = '../../escaped'", "out/<name>", "plain file name", "-o"]),
    ("name-is-absolute", ["run", "{dir}/absolute.toml"], ["key 'name' = '{dir}/escaped'", "out/<name>", "-o"]),
    ("name-leaves-out-compare", ["compare", "{dir}/climb.toml"], ["key 'name' = '../../escaped'", "-o"]),
    ("name-leaves-out-kinematics", ["kinematics", "{dir}/climb.toml"], ["key 'name' = '../../escaped'", "-o"]),
    ("kinematics-sample-deg-1e-9", ["kinematics", "{dir}/fine.toml"],
     ["output.sample_deg = 1e-09 over one revolution", "3.6e+11 output samples"]),
    ("compare-sample-deg-1e-9", ["compare", "{dir}/fine.toml"], ["output.sample_deg = 1e-09", "7.2e+11"]),
]


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """Run every row of SCENES and FLAGS; id -> (CompletedProcess, directory)."""
    jobs = {}
    for name, text, _ in SCENES:
        directory = tmp_path_factory.mktemp(name)
        if name in HOSTILE_ROWS:
            make_hostile_files(directory)
        (directory / "scene.toml").write_text(text)
        jobs[f"scene:{name}"] = (["run", directory / "scene.toml", "-o", directory / "out"], directory)
    for name, args, _ in FLAGS:
        directory = tmp_path_factory.mktemp(name)
        (directory / "blocker").write_text("x")
        (directory / "thesis").mkdir()
        (directory / "thesis" / "chapter1.tex").write_text("mine")
        (directory / "latin1.toml").write_bytes("name = \"caf\xe9\"\n".encode("latin-1"))
        (directory / "nan.toml").write_text(EXTENDS + "[drive]\nspeed_rpm = nan\n")
        (directory / "fine.toml").write_text(EXTENDS + "[output]\nsample_deg = 1e-9\n")
        (directory / "climb.toml").write_text(EXTENDS + 'name = "../../escaped"\n')
        (directory / "absolute.toml").write_text(EXTENDS + f'name = "{directory}/escaped"\n')
        os.mkfifo(directory / "fifo")
        subst = [str(a).replace("{scene}", str(REFERENCE)).replace("{dir}", str(directory)) for a in args]
        jobs[f"flag:{name}"] = (subst, directory)
    return {key: ((cli if key in BLOCKING else cli_in_process)(*args, cwd=directory), directory)
            for key, (args, directory) in jobs.items()}


def assert_one_clear_line(done: subprocess.CompletedProcess, words) -> None:
    assert done.returncode == EXIT_USAGE, (done.returncode, done.stderr, done.stdout)
    assert "Traceback" not in done.stderr
    assert "\x1b" not in done.stderr  # no terminal escape sequence reaches the terminal raw
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "error" in lines[0]
    for word in words:
        assert word in lines[0], (word, lines[0])


@pytest.mark.parametrize("name, text, words", SCENES, ids=[row[0] for row in SCENES])
def test_bad_scene_file(outcomes, name, text, words):
    done, directory = outcomes[f"scene:{name}"]
    assert_one_clear_line(done, words)
    if name not in NAMES_A_SYSTEM_FILE:
        assert str(directory) in done.stderr  # the file is named (the scene or the one it extends)
    assert not (directory / "out").exists()  # refused before anything is written


@pytest.mark.parametrize("name, args, words", FLAGS, ids=[row[0] for row in FLAGS])
def test_bad_flag_or_output(outcomes, name, args, words):
    done, directory = outcomes[f"flag:{name}"]
    words = [w.replace("{dir}", str(directory)) for w in words]
    assert_one_clear_line(done, words)
    # Run in the test directory: a refused command creates no default out/ there, and nothing
    # lands where a scene's name points outside it.
    assert not (directory / "out").exists()
    assert not (directory.parent.parent / "escaped").exists() and not (directory / "escaped").exists()
    # A refused directory keeps exactly what it held.
    assert (directory / "blocker").read_text() == "x"
    assert [p.name for p in (directory / "thesis").iterdir()] == ["chapter1.tex"]


def test_every_scene_key_section_is_covered_by_the_table():
    """The table reaches every section of the schema with at least one bad value."""
    from weftsim.input.scene import SCHEMA

    sections = {key.path.split(".")[0] for key in SCHEMA}
    text = "".join(text for _, text, _ in SCENES)
    missing = [s for s in sections if f"[{s}" not in text and s != "compare"]
    assert not missing, missing


# --- Output directories: no mixing, atomic files ----------------------------------------


def test_foreign_directory_is_used_only_with_force_and_its_files_stay(tmp_path):
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("mine")
    done = cli_in_process("run", REFERENCE, "-o", out, "--revolutions", "0.01", "--no-plot", "--force", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (out / "chapter1.tex").read_text() == "mine"  # --force writes beside, never deletes others' files
    assert {"channels.csv", "summary.json", "chapter1.tex"} <= {p.name for p in out.iterdir()}


def test_rerun_replaces_the_previous_run_and_drops_its_stale_files(tmp_path):
    out = tmp_path / "run"
    first = cli_in_process("run", REFERENCE, "-o", out, "--revolutions", "0.01", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert (out / "channels.png").exists()
    # Another scene (0.02 revolutions) into the same directory: refused unless --force (issue 25).
    refused = cli_in_process("run", REFERENCE, "-o", out, "--revolutions", "0.02", "--no-plot", cwd=tmp_path)
    assert refused.returncode == 2 and "drive.revolutions 0.01 -> 0.02" in refused.stderr
    second = cli_in_process("run", REFERENCE, "-o", out, "--revolutions", "0.02", "--no-plot", "--force", cwd=tmp_path)
    assert second.returncode == 0, second.stderr
    # The figure of the first run would describe other data: it is gone, and the manifest lists
    # exactly this run's files.
    assert not (out / "channels.png").exists()
    manifest = json.loads((out / ".weftsim-output.json").read_text())
    assert manifest["files"] == ["channels.csv", "result.npz", "scene.toml", "summary.json"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scene"]["drive.revolutions"] == 0.02


# A run whose CSV writer stops half way through the temporary file, tells the test it is there,
# and waits to be killed.
_SLOW_WRITER = r"""
import sys, time
from pathlib import Path
import numpy as np
import weftsim.post.output as output

real = np.savetxt
def half_then_hang(path, table, **kw):
    real(path, table[: len(table) // 2], **kw)
    Path(sys.argv[1]).write_text(str(path))
    time.sleep(600)
output.np.savetxt = half_then_hang
from weftsim.cli.commands import main
sys.exit(main(sys.argv[2:]))
"""


def test_sigkill_while_writing_leaves_the_previous_complete_files(tmp_path):
    out = tmp_path / "run"
    first = cli("run", REFERENCE, "-o", out, "--revolutions", "0.02", "--no-plot")
    assert first.returncode == 0, first.stderr
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    ready = tmp_path / "ready"
    child = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(ready), "run", str(REFERENCE), "-o", str(out),
                              "--revolutions", "0.05", "--no-plot", "--force"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not ready.exists():
            assert child.poll() is None, "the run ended before it wrote"
            assert time.monotonic() < deadline, "the run never reached its CSV"
            time.sleep(0.05)
        os.kill(child.pid, signal.SIGKILL)
        child.wait(timeout=30)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == -signal.SIGKILL
    # Killed in the middle of channels.csv: every result file under its final name is the previous
    # run's, complete and byte for byte; the half-written data sits in a hidden temporary file only,
    # and the manifest says the directory was being written when the run died.
    after = {p.name: p for p in out.iterdir()}
    for name, data in before.items():
        if name != MANIFEST:
            assert after[name].read_bytes() == data, name
    assert json.loads(after[MANIFEST].read_text())["state"] == "writing"
    partial = [name for name in after if name not in before]
    assert partial and all(name.startswith(".channels.csv.") and name.endswith(".part") for name in partial)
    # The next run into the directory works and leaves its own complete files.
    again = cli("run", REFERENCE, "-o", out, "--revolutions", "0.03", "--no-plot", "--force")
    assert again.returncode == 0, again.stderr
    assert json.loads((out / "summary.json").read_text())["scene"]["drive.revolutions"] == 0.03
    assert json.loads((out / MANIFEST).read_text())["state"] == "complete"
    assert not [p for p in out.iterdir() if p.name.endswith(".part")]  # the killed run's leftovers are gone
