"""Signals at awkward moments (issue 35): Ctrl-C while the run-time estimate imports the engine, an
engine's ImportError raised by a Ctrl-C, SIGTERM during a wear ensemble (it says how to resume, as wear does),
and the ensemble's progress lines giving the time left."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from weftsim.cli.commands import main

REFERENCE = Path(__file__).resolve().parents[1] / "models" / "reference.toml"


def test_ctrl_c_while_the_estimate_imports_the_engine_stops_the_run(monkeypatch, tmp_path, capsys):
    """The estimate imports the engine (Exudyn for the default one): a Ctrl-C there now lands in the run's stop
    handler, so the run stops at its first step, keeps what it computed and says so, with no traceback."""
    def estimate(scene, engines, command):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # the handler runs at the next bytecode

    monkeypatch.setattr("weftsim.cli.commands._announce_run_time", estimate)
    out = tmp_path / "r"
    status = main(["run", "reference", "--engine", "reference", "--revolutions", "0.5", "--no-plot", "-o", str(out)])
    err = capsys.readouterr().err
    assert status == 130, err
    assert "stopped by Ctrl-C, SIGINT" in err and "Traceback" not in err
    assert (out / "summary.json").is_file()


def test_an_import_error_raised_by_a_ctrl_c_is_an_interruption(monkeypatch, capsys):
    def cmd(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise ImportError("cannot import the compiled module exudynCPP")  # what Exudyn's loader does

    monkeypatch.setitem(__import__("weftsim.cli.commands").cli.commands.COMMANDS, "scenes", cmd)
    assert main(["scenes"]) == 130
    assert capsys.readouterr().err.strip() == "weftsim scenes: interrupted"


def test_a_real_import_error_is_not_called_an_interruption(monkeypatch):
    def cmd(args):
        raise ImportError("no module named exudynCPP")

    monkeypatch.setitem(__import__("weftsim.cli.commands").cli.commands.COMMANDS, "scenes", cmd)
    with pytest.raises(ImportError):
        main(["scenes"])


def test_sigterm_during_an_ensemble_says_how_to_resume(tmp_path):
    out = tmp_path / "ens"
    cmd = [sys.executable, "-m", "weftsim.cli", "wear", str(REFERENCE), "--uncertain",
           "joint_e.wear.wear_coefficient=lognormal(1e-7,0.5)", "--uncertain", "speed_rpm=uniform(390,410)",
           "--chaos-runs", "2", "--samples", "50", "--limit-clearance-mm", "0.26", "--jobs", "1", "--no-plot",
           "-o", str(out)]
    process = subprocess.Popen(cmd, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    lines = []
    for line in process.stderr:  # wait for the first finished job: the pool is running
        lines.append(line)
        if "ensemble: job " in line:
            break
    assert "~" in lines[-1] and "left" in lines[-1], lines  # a time left after the first of four jobs
    process.send_signal(signal.SIGTERM)
    rest = process.stderr.read()
    process.wait(timeout=120)
    assert process.returncode == 128 + signal.SIGTERM, rest
    assert "terminated by SIGTERM" in rest and "run the same command again to resume" in rest, rest
    assert "Traceback" not in rest
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    assert again.returncode == 0, again.stderr


_START = ("import os, signal, sys, time\n"
          "sys.argv = [{argv0!r}]\n"
          "{ignore}"
          "import weftsim\n"
          "os.kill(os.getpid(), signal.SIGINT)\n"
          "time.sleep(0.5)\n"
          "print('still running')\n")


def _start(argv0: str, ignore: bool = False) -> subprocess.CompletedProcess:
    code = _START.format(argv0=argv0, ignore="signal.signal(signal.SIGINT, signal.SIG_IGN)\n" if ignore else "")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def test_ctrl_c_while_the_command_imports_is_one_line():
    """A Ctrl-C in the first ~0.4 s of `weftsim run reference` (numpy, scipy, numba loading before main()
    can catch it) printed a KeyboardInterrupt traceback of whatever module was loading, or that module's
    ImportError/RuntimeError (measured here: every delay from 0.05 to 0.3 s).  In the weftsim command's own
    process the SIGINT that arrives while it imports ends it with one line and status 130."""
    done = _start("/somewhere/bin/weftsim")
    assert done.returncode == 130, done.stderr
    assert done.stderr == "weftsim: interrupted while starting\n" and "still running" not in done.stdout


def test_a_library_import_and_an_ignored_sigint_are_left_alone():
    """Importing weftsim from another program changes no signal handler (a Ctrl-C stays its KeyboardInterrupt),
    and a command started with SIGINT ignored (a background job of a script) keeps ignoring it."""
    library = _start("/somewhere/bin/myscript")
    assert library.returncode == -signal.SIGINT and "KeyboardInterrupt" in library.stderr, library.stderr
    ignored = _start("/somewhere/bin/weftsim", ignore=True)
    assert ignored.returncode == 0 and "still running" in ignored.stdout, ignored.stderr


def test_main_gives_sigint_back_before_the_command_runs(monkeypatch):
    """Once main() has parsed the command line, a Ctrl-C is a KeyboardInterrupt again, which the commands turn
    into their own lines (the run's stop handler, 'interrupted')."""
    import weftsim.cli.startup as startup

    seen = {}

    def cmd(args):
        seen["handler"] = signal.getsignal(signal.SIGINT)
        return 0

    monkeypatch.setitem(__import__("weftsim.cli.commands").cli.commands.COMMANDS, "scenes", cmd)
    previous = signal.signal(signal.SIGINT, startup._stop)
    try:
        assert main(["scenes"]) == 0
    finally:
        signal.signal(signal.SIGINT, previous)
    assert seen["handler"] is signal.default_int_handler
