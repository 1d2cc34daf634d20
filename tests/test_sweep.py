"""Design sweeps: grid parsing, validation of every cell, the table, failures, resume and refusal.

The machinery is exercised with :func:`fake_solve`, a closed-form "engine" (ideal
kinematics, synthetic contact force) that costs milliseconds, so these tests check
the sweep, not the physics.  Its peaks are known exactly, which lets the tests
check that the table reports the peaks of the right run in the right row.
"""

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from weftsim.cli.commands import EXIT_FAILED, EXIT_USAGE, main
from weftsim.post.results import CHANNELS, RunResult
from weftsim.sweep import plan_sweep, run_sweep
from weftsim.sweep.cell import CELL_FILE, ERROR_FILE
from weftsim.sweep.grid import SweepError, cell_name, grid_cells, parse_set, parse_vary
from weftsim.sweep.store import TABLE_FILE, read_table

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "models" / "reference.toml"
FAKE = "test_sweep:fake_solve"
SHORT = ["revolutions=0.5"]  # fixed override: half a revolution keeps every file small
RAISE_RESTITUTION = 0.2  # fake_solve raises at this restitution
FAILED_RESTITUTION = 0.3  # fake_solve returns a failed RunResult at this restitution
CRASH_RESTITUTION = 0.1  # fake_solve kills its worker process at this restitution


def fake_solve(scene, progress=None):
    """Closed-form stand-in for an engine: ideal rapier kinematics, torque from the rapier's power.

    Driving torque T = m8 a v / omega (the power the crank gives to the rapier mass
    alone) and a synthetic contact force F = 1e3 c[mm] omega^2 (1 + sin theta) / 2,
    so every peak is known.  ``WEFTSIM_FAKE_DELAY_S`` in the environment makes each
    call sleep that long; ``WEFTSIM_FAKE_GATE_DIR`` lets only ``WEFTSIM_FAKE_FAST_CELLS`` calls
    finish (for the kill-and-resume test).
    """
    from weftsim.mechanism.kinematics import rapier_motion

    time.sleep(float(os.environ.get("WEFTSIM_FAKE_DELAY_S", "0")))
    gate = os.environ.get("WEFTSIM_FAKE_GATE_DIR")
    if gate:  # only the first WEFTSIM_FAKE_FAST_CELLS calls finish; later ones hang until killed
        for slot in range(int(os.environ["WEFTSIM_FAKE_FAST_CELLS"])):
            try:
                os.close(os.open(os.path.join(gate, f"slot-{slot}"), os.O_CREAT | os.O_EXCL))
                break
            except FileExistsError:
                continue
        else:
            time.sleep(600)
    restitution = scene.joint.restitution
    if restitution == CRASH_RESTITUTION:
        os._exit(17)  # a hard crash of the worker (like a segfault in compiled code)
    if restitution == RAISE_RESTITUTION:
        raise RuntimeError("fake engine: impossible setting")
    omega = scene.drive.speed

    def channels(step_angle):
        theta = np.linspace(0.0, scene.drive.revolutions * 2 * math.pi,
                            int(round(scene.drive.revolutions * 2 * math.pi / step_angle)) + 1)
        s, v, a = rapier_motion(theta, omega, scene.geometry)
        data = {name: np.zeros_like(theta) for name in CHANNELS}
        data.update(time_s=theta / omega, crank_angle_deg=np.degrees(theta), rapier_displacement_m=s,
                    rapier_velocity_m_s=v, rapier_acceleration_m_s2=a,
                    driving_torque_Nm=scene.inertia.rapier_mass * a * v / omega,
                    contact_force_N=1e3 * scene.joint.clearance * 1e3 * omega**2 * (1 + np.sin(theta)) / 2)
        return data

    failed = restitution == FAILED_RESTITUTION
    return RunResult(scene, "reference", "failed" if failed else "success",
                     "fake engine: step size too small at t = 0.01 s" if failed else "",
                     channels(scene.output.sample_angle), channels(math.radians(0.25)),
                     {"wall_time_s": 0.001})


def fake_peaks(clearance_mm, speed_rpm, revolutions=0.5):
    """The peaks fake_solve's per-step channels reach (same 0.25 deg grid)."""
    from weftsim.mechanism.kinematics import rapier_motion
    from weftsim.input.scene import load_scene

    scene = load_scene(REFERENCE)
    omega = speed_rpm * math.pi / 30
    theta = np.linspace(0.0, revolutions * 2 * math.pi, int(round(revolutions * 1440)) + 1)
    s, v, a = rapier_motion(theta, omega, scene.geometry)
    return {"acceleration": np.abs(a).max(), "torque": np.abs(scene.inertia.rapier_mass * a * v / omega).max(),
            "contact": (1e3 * clearance_mm * omega**2 * (1 + np.sin(theta)) / 2).max()}


def sweep(outdir, vary, fixed=SHORT, engine=FAKE, **kwargs):
    plan = plan_sweep(REFERENCE, vary, fixed, engine)
    return run_sweep(plan, outdir, progress=False, **kwargs)


# --- grid parsing -------------------------------------------------------------------------------------


def test_lists_and_inclusive_ranges_parse_in_file_units():
    assert parse_vary("clearance_mm=0.01,0.25,0.5").values == (0.01, 0.25, 0.5)
    speed = parse_vary("speed_rpm=300:800:6")
    assert (speed.key, speed.name) == ("drive.speed_rpm", "speed_rpm")
    assert speed.values == (300.0, 400.0, 500.0, 600.0, 700.0, 800.0)  # both ends included
    # linspace gives 0.08000000000000002; rounding to 12 digits keeps names and values clean.
    assert parse_vary("clearance_mm=0.01:0.5:8").values[1] == 0.08
    assert parse_vary("joint_e.law=hunt_crossley,variable_kd").values == ("hunt_crossley", "variable_kd")
    assert parse_vary("newton_max_iterations=10:30:3").values == (10, 20, 30)
    assert parse_vary("modified_newton=true,false").values == (True, False)
    assert parse_set("revolutions=0.5") == ("drive.revolutions", 0.5)


@pytest.mark.parametrize("text, words", [
    ("clearnce_mm=0.1", ["unknown scene key 'clearnce_mm'", "did you mean clearance_mm"]),
    ("youngs_modulus_gpa=200", ["ambiguous", "joint_e.journal_material.youngs_modulus_gpa"]),
    ("speed_rpm=300:800", ["start:stop:count"]),
    ("speed_rpm=300:800:1", ["at least 2"]),
    ("speed_rpm=300:800:x", ["whole number"]),
    ("speed_rpm=fast,slow", ["takes a number", "'fast'"]),
    ("speed_rpm=400,400.0", ["400", "more than once"]),
    ("speed_rpm=", ["no values"]),
    ("law=a:b:3", ["not numeric"]),
    ("law=variable kd", ["letters, digits", "write _: 'variable_kd'"]),
    ("law=variable kd!", ["letters, digits"]),
    ("newton_max_iterations=10:20:4", ["non-whole"]),
    ("friction_velocities_m_s=1", ["cannot be swept"]),
    ("clearance_mm", ["KEY=VALUES"]),
])
def test_bad_vary_text_gives_one_clear_error(text, words):
    with pytest.raises(SweepError) as info:
        parse_vary(text)
    for word in words:
        assert word in str(info.value)


def test_cell_names_sort_parameters_so_flag_order_does_not_matter():
    assert cell_name({"speed_rpm": 400.0, "clearance_mm": 0.25}) == "clearance_mm=0.25,speed_rpm=400"
    axes = [parse_vary("speed_rpm=300,400"), parse_vary("clearance_mm=0.25")]
    cells = grid_cells(axes, {"drive.revolutions": 0.5})
    assert [c.name for c in cells] == ["clearance_mm=0.25,speed_rpm=300", "clearance_mm=0.25,speed_rpm=400"]
    assert cells[0].overrides == {"drive.revolutions": 0.5, "drive.speed_rpm": 300.0, "joint_e.clearance_mm": 0.25}
    with pytest.raises(SweepError, match="more than once"):
        grid_cells([parse_vary("speed_rpm=300"), parse_vary("drive.speed_rpm=400")])
    with pytest.raises(SweepError, match="both varied"):
        grid_cells([parse_vary("revolutions=1,2")], {"drive.revolutions": 0.5})


def test_every_cell_is_validated_before_anything_runs(tmp_path):
    # 12 mm is above the schema's 5 mm limit and -0.1 is negative: both named, nothing run or written.
    with pytest.raises(SweepError) as info:
        plan_sweep(REFERENCE, ["clearance_mm=0.1,12,-0.1", "speed_rpm=300,400"], SHORT, FAKE)
    message = str(info.value)
    assert "4 of 6 cells are invalid, nothing was run" in message
    assert "must be >= 0 and <= 5, got 12" in message and "clearance_mm=12,speed_rpm=300" in message
    assert "got -0.1" in message and "clearance_mm=-0.1,speed_rpm=400" in message
    with pytest.raises(SweepError, match="must be one of"):
        plan_sweep(REFERENCE, ["law=no_such_law"], SHORT, FAKE)
    with pytest.raises(SweepError, match="--engine"):
        plan_sweep(REFERENCE, ["clearance_mm=0.1"], SHORT, "warp_drive")
    assert main(["sweep", str(REFERENCE), "--vary", "speed_rpm=-5,300", "-o", str(tmp_path / "x")]) == EXIT_USAGE
    assert not (tmp_path / "x").exists()


# --- running ------------------------------------------------------------------------------------------


def test_twelve_cell_sweep_tabulates_the_peaks_of_each_cell(tmp_path):
    report = sweep(tmp_path, ["clearance_mm=0.01,0.25,0.5", "speed_rpm=300:600:4"], jobs=2)
    assert (report.total, report.succeeded, report.failed, report.skipped) == (12, 12, 0, 0)
    rows = read_table(tmp_path / TABLE_FILE)
    assert len(rows) == 12 and {r["status"] for r in rows} == {"success"}
    assert [r["cell"] for r in rows[:2]] == ["clearance_mm=0.01,speed_rpm=300", "clearance_mm=0.01,speed_rpm=400"]
    for row in rows:
        expected = fake_peaks(float(row["clearance_mm"]), float(row["speed_rpm"]))
        # The table holds 10 significant digits.
        assert float(row["rapier_acceleration_m_s2_rev1_peak"]) == pytest.approx(expected["acceleration"], rel=1e-9)
        assert float(row["driving_torque_Nm_rev1_peak"]) == pytest.approx(expected["torque"], rel=1e-9)
        assert float(row["contact_force_N_rev1_peak"]) == pytest.approx(expected["contact"], rel=1e-9)
        assert row["contact_force_N_p99"] == ""  # half a revolution: no statistics over revolutions 2..N
        assert (tmp_path / row["cell"] / "summary.json").exists()
        assert (tmp_path / row["cell"] / "channels.csv").exists()
    # Kinematics scale with speed squared: 600 rpm has 4 times the peak acceleration of 300 rpm.
    acc = {float(r["speed_rpm"]): float(r["rapier_acceleration_m_s2_rev1_peak"]) for r in rows}
    assert acc[600.0] / acc[300.0] == pytest.approx(4.0, rel=1e-9)  # exact law, 10-digit table
    assert report.figure.stat().st_size > 20_000


def test_failed_cells_are_recorded_and_the_others_complete(tmp_path):
    values = f"restitution={RAISE_RESTITUTION},{FAILED_RESTITUTION},0.9"
    report = sweep(tmp_path, [values, "speed_rpm=300,400"], jobs=2)
    assert (report.succeeded, report.failed) == (2, 4)
    rows = {r["cell"]: r for r in read_table(tmp_path / TABLE_FILE)}
    raised = rows[f"restitution={RAISE_RESTITUTION},speed_rpm=300"]
    assert raised["status"] == "failed" and "impossible setting" in raised["error"]
    text = (tmp_path / raised["cell"] / ERROR_FILE).read_text()
    assert "RuntimeError: fake engine: impossible setting" in text and "Traceback" in text
    engine_failed = rows[f"restitution={FAILED_RESTITUTION},speed_rpm=400"]
    assert engine_failed["status"] == "failed" and "step size too small" in engine_failed["error"]
    # A run that failed keeps what it computed: its partial peaks are in the table.
    assert float(engine_failed["rapier_acceleration_m_s2_rev1_peak"]) > 0
    assert rows["restitution=0.9,speed_rpm=300"]["status"] == "success"


def test_the_command_line_exits_3_when_cells_fail(tmp_path, capsys):
    status = main(["sweep", str(REFERENCE), "--vary", f"restitution={RAISE_RESTITUTION},0.9", "--set",
                   "revolutions=0.5", "--engine", FAKE, "-o", str(tmp_path), "--jobs", "1"])
    assert status == EXIT_FAILED
    captured = capsys.readouterr()
    assert "1 of 2 cells failed" in captured.err
    assert "sweep.csv" in captured.out


def test_a_crashing_worker_is_retried_alone_then_recorded(tmp_path):
    report = sweep(tmp_path, [f"restitution={CRASH_RESTITUTION},0.9", "speed_rpm=300,400"], jobs=2)
    assert (report.succeeded, report.failed) == (2, 2)
    rows = {r["cell"]: r for r in read_table(tmp_path / TABLE_FILE)}
    crashed = rows[f"restitution={CRASH_RESTITUTION},speed_rpm=300"]
    assert crashed["status"] == "failed" and "worker process died" in crashed["error"]
    assert (tmp_path / crashed["cell"] / ERROR_FILE).exists()


# --- resume and refusal -------------------------------------------------------------------------------


def _mtimes(outdir):
    return {p: p.stat().st_mtime_ns for p in Path(outdir).glob("*/*") if p.is_file()}


def test_rerun_skips_finished_cells_and_a_superset_grid_runs_only_new_cells(tmp_path):
    sweep(tmp_path, ["clearance_mm=0.1,0.2", "speed_rpm=300,400"], jobs=1)
    before = _mtimes(tmp_path)
    again = sweep(tmp_path, ["speed_rpm=300,400", "clearance_mm=0.1,0.2"], jobs=1)  # flags in another order
    assert (again.skipped, again.succeeded) == (4, 0)
    wider = sweep(tmp_path, ["clearance_mm=0.1,0.2,0.3", "speed_rpm=300,400"], jobs=1)
    assert (wider.skipped, wider.succeeded) == (4, 2)
    assert all(_mtimes(tmp_path)[p] == t for p, t in before.items())  # finished cells untouched
    # A cell whose manifest does not match its scene (e.g. edited by hand) is run again.
    (tmp_path / "clearance_mm=0.1,speed_rpm=300" / CELL_FILE).write_text('{"format": "weftsim-sweep-cell/1"}')
    assert sweep(tmp_path, ["clearance_mm=0.1", "speed_rpm=300"], jobs=1).succeeded == 1
    assert len(read_table(tmp_path / TABLE_FILE)) == 6  # the table covers every cell on disk


def test_a_directory_holding_another_sweep_is_refused(tmp_path):
    sweep(tmp_path, ["clearance_mm=0.1,0.2"], jobs=1)
    with pytest.raises(SweepError, match=r"different sweep .*drive.revolutions = 0.5 there, 1.0 here"):
        sweep(tmp_path, ["clearance_mm=0.1,0.2"], fixed=["revolutions=1"])
    with pytest.raises(SweepError, match="varied keys joint_e.clearance_mm there, drive.speed_rpm here"):
        sweep(tmp_path, ["speed_rpm=300"])
    with pytest.raises(SweepError, match="engine"):
        sweep(tmp_path, ["clearance_mm=0.1"], engine="reference")
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(SweepError, match="not empty and holds no sweep.json"):
        sweep(other, ["clearance_mm=0.1"])


def _terminal_sigint() -> None:
    """In the child before exec: SIGINT delivered and handled as in a terminal.

    A signal mask and ignored signals are inherited through fork and exec; in the whole suite the
    sweep child once never saw the Ctrl-C (it ran to the 60 s timeout), while the test alone passed.
    """
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT], ids=["SIGKILL", "Ctrl-C"])
def test_interrupted_sweep_resumes_without_losing_or_redoing_finished_cells(tmp_path, sig):
    """Kill (or Ctrl-C) the whole `weftsim sweep` process group mid-sweep, then run the same command again."""
    outdir = tmp_path / "sweep"
    command = [sys.executable, "-m", "weftsim.cli", "sweep", str(REFERENCE), "--vary", "clearance_mm=0.1,0.2,0.3",
               "--vary", "speed_rpm=300:600:4", "--set", "revolutions=0.5", "--engine", FAKE, "--jobs", "2",
               "-o", str(outdir)]
    gate = tmp_path / "gate"
    gate.mkdir()
    # Exactly 4 cells can finish before the interrupt, however loaded the machine: the others hang.
    env = {**os.environ, "PYTHONPATH": str(ROOT / "tests"), "WEFTSIM_FAKE_DELAY_S": "0.2",
           "WEFTSIM_FAKE_GATE_DIR": str(gate), "WEFTSIM_FAKE_FAST_CELLS": "4"}
    process = subprocess.Popen(command, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True, preexec_fn=_terminal_sigint)
    deadline = time.monotonic() + 120  # generous: a loaded 2-core machine; the loop normally takes ~2 s
    try:
        while len(list(outdir.glob(f"*/{CELL_FILE}"))) < 4:
            assert process.poll() is None, "the sweep ended before it could be interrupted"
            assert time.monotonic() < deadline, "no cell finished in time"
            time.sleep(0.05)
    finally:
        os.killpg(process.pid, sig)  # the whole group, as a terminal's Ctrl-C does: workers too
        _, err = process.communicate(timeout=60)
    if sig == signal.SIGINT:
        assert process.returncode == 130 and "interrupted" in err
        statuses = [r["status"] for r in read_table(outdir / TABLE_FILE)]  # rewritten on the way out
        assert len(statuses) == 12 and "pending" in statuses
    finished = sorted(p.parent for p in outdir.glob(f"*/{CELL_FILE}"))
    assert len(finished) == 4
    before = {p: p.stat().st_mtime_ns for d in finished for p in d.iterdir()}
    env["WEFTSIM_FAKE_DELAY_S"] = "0"
    del env["WEFTSIM_FAKE_GATE_DIR"]
    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"{len(finished)} already finished" in done.stdout
    assert all(p.stat().st_mtime_ns == t for p, t in before.items())
    rows = read_table(outdir / TABLE_FILE)
    assert len(rows) == 12 and {r["status"] for r in rows} == {"success"}


# --- the real engine ------------------------------------------------------------------------------------


def test_reference_engine_sweep_of_twelve_cells(tmp_path):
    """Twelve short reference-engine cells: ideal cells give the closed-form kinematics, clearance adds contact."""
    from weftsim.mechanism.kinematics import rapier_motion
    from weftsim.input.scene import load_scene

    report = sweep(tmp_path, ["clearance_mm=0,0.1,0.25,0.5", "speed_rpm=300,400,800"], ["revolutions=0.25"],
                   engine="reference", jobs=2)
    assert (report.succeeded, report.failed) == (12, 0)
    rows = read_table(tmp_path / TABLE_FILE)
    peak = {(float(r["clearance_mm"]), float(r["speed_rpm"])): float(r["rapier_acceleration_m_s2_rev1_peak"])
            for r in rows}
    contact = {(float(r["clearance_mm"]), float(r["speed_rpm"])): r["contact_force_N_rev1_peak"] for r in rows}
    geometry = load_scene(REFERENCE).geometry
    theta = np.linspace(0.0, math.pi / 2, 90_001)  # 0.001 deg over the quarter revolution that was run
    for rpm in (300.0, 400.0, 800.0):
        exact = np.abs(rapier_motion(theta, rpm * math.pi / 30, geometry)[2]).max()
        # Ideal joint: closed form sampled at 0.1 deg; sampling a smooth peak costs < 1e-4 relative.
        assert peak[(0.0, rpm)] == pytest.approx(exact, rel=1e-4)
        assert contact[(0.0, rpm)] == ""  # the ideal joint has no contact force: an empty cell, not 0 (issue 24)
        assert all(r["contact_force_f_N_rev1_peak"] == "" for r in rows)  # F ideal in every cell
        for clearance in (0.1, 0.25, 0.5):
            assert float(contact[(clearance, rpm)]) > 0.0
            # Paper Figs. 12-13: the impacts at E raise the rapier acceleration above the ideal peak.
            assert peak[(clearance, rpm)] > peak[(0.0, rpm)]


def test_the_sweep_table_has_each_joints_load_and_its_film_and_asperity_shares():
    """Issue 35: a cell without oil showed its dry law's 2 kN where the joint carried 54.9 kN on its asperities.
    The table now has joint_force_N (film + asperities + dry law), film_force_N and asperity_force_N: their peaks
    are the run's (a lubricated cell), a dry cell's film and asperity columns are empty (None)."""
    from weftsim.input.scene import load_scene
    from weftsim.post.analysis import peaks
    from weftsim.reference import solve
    from weftsim.sweep.cell import cell_metrics

    oiled = solve(load_scene("reference", {"drive.revolutions": 0.1, "joint_e.lubrication.viscosity_mpa_s": 80.0}))
    dry = solve(load_scene("reference", {"drive.revolutions": 0.1}))
    metrics, first = cell_metrics(oiled), peaks(oiled, 0)
    for channel in ("joint_force_N", "film_force_N", "asperity_force_N", "contact_force_N"):
        assert metrics[f"{channel}_rev1_peak"] == max(abs(first[channel]["min"]), abs(first[channel]["max"]))
    assert metrics["joint_force_N_rev1_peak"] > metrics["contact_force_N_rev1_peak"]  # the film carries load
    dry_metrics = cell_metrics(dry)
    assert dry_metrics["film_force_N_rev1_peak"] is None and dry_metrics["asperity_force_N_rev1_peak"] is None
    assert dry_metrics["joint_force_N_rev1_peak"] == dry_metrics["contact_force_N_rev1_peak"]
