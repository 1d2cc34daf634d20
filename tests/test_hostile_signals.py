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
