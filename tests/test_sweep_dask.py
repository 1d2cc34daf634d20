"""The distributed path: the same cells on a Dask cluster without a shared file system give the same
table as the local pool, and a killed client loses nothing the cluster had returned.

The cluster is started by the test on the loopback interface (two worker processes, one
thread each) and closed at the end; the sweep reaches it through ``--scheduler``.  Its workers
are made to stand where a cloud or Kubernetes worker stands (:class:`ElsewhereWorker`): each runs
in its own working directory, and an audit hook (PEP 578) in each worker process refuses every
open, listing, creation, rename or removal of a path under the test's directories (where the
sweeps are written) and under ``models/`` (where the scene files are), and records the attempt.
A sweep that passes here therefore never had a worker read the scene file or write the sweep
directory: the scene went out as data and the results came back to the client.  What it does not
prove: workers on another machine (another Python, another weftsim version) behave the same.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from weftsim.cli.commands import EXIT_FAILED, main
from weftsim.post.record import MANIFEST
from weftsim.sweep import plan_sweep, run_sweep
from weftsim.sweep.cell import CELL_FILE, is_finished, read_record
from weftsim.sweep.store import TABLE_FILE, read_table

distributed = pytest.importorskip("dask.distributed")

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "models" / "reference.toml"
TIMING_COLUMNS = ("wall_time_s",)  # the only columns allowed to differ between two runs of the same cells


FAKE = "test_sweep:fake_solve"
BLOCKED: list = []  # in a worker process: the guarded paths it tried to touch
PATH_EVENTS = {"open": 1, "os.mkdir": 1, "os.listdir": 1, "os.scandir": 1, "os.remove": 1, "os.rmdir": 1,
               "os.rename": 2, "os.replace": 2, "os.chmod": 1, "os.utime": 1, "os.symlink": 2, "os.link": 2}


def _guard(roots):
    def hook(event, args):
        for arg in args[:PATH_EVENTS.get(event, 0)]:
            if isinstance(arg, (str, bytes, os.PathLike)):
                path = os.path.abspath(os.fsdecode(arg))
                if any(path == root or path.startswith(root + os.sep) for root in roots):
                    BLOCKED.append((event, path))
                    raise PermissionError(f"this worker cannot see {path}")

    return hook


class ElsewhereWorker(distributed.WorkerPlugin):
    """Moves a worker into ``cwd``, sets ``env`` and makes the paths under ``hidden`` invisible to it."""

    def __init__(self, cwd: str, hidden: list[str], env: dict | None = None):
        self.cwd, self.hidden, self.env = cwd, [os.path.realpath(h) for h in hidden], env or {}

    def setup(self, worker):
        os.chdir(self.cwd)
        os.environ.update(self.env)
        sys.addaudithook(_guard(self.hidden))


def _blocked():
    return list(BLOCKED)


def _forget_blocked():
    BLOCKED.clear()


def _try_to_read(path):
    try:
        open(path).close()
    except PermissionError:
        return "refused"
    return "read"


def blind_cluster(tmp_root: Path, env: dict | None = None):
    """A LocalCluster whose workers run in a directory of their own, blind to ``tmp_root`` and models/."""
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                       dashboard_address=None)
    elsewhere = tempfile.mkdtemp(prefix="weftsim-worker-cwd-")
    with distributed.Client(cluster) as client:
        client.register_plugin(ElsewhereWorker(elsewhere, [str(tmp_root), str(ROOT / "models")], env))
        assert set(client.run(os.getcwd).values()) == {os.path.realpath(elsewhere)}
        # The guard works: a worker cannot read the scene file the client reads.
        assert set(client.run(_try_to_read, str(REFERENCE)).values()) == {"refused"}
        client.run(_forget_blocked)  # that refusal was the test's own
    return cluster, elsewhere


def check_workers_stayed_blind(address: str, elsewhere: str) -> None:
    with distributed.Client(address) as client:
        blocked = client.run(_blocked)
    assert all(attempts == [] for attempts in blocked.values()), blocked
    assert os.listdir(elsewhere) == []  # nothing written in the workers' own working directory either


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    cluster, elsewhere = blind_cluster(tmp_path_factory.getbasetemp())
    with cluster:
        yield cluster.scheduler_address
        check_workers_stayed_blind(cluster.scheduler_address, elsewhere)
    shutil.rmtree(elsewhere, ignore_errors=True)


def _table(path):
    return [{k: v for k, v in row.items() if k not in TIMING_COLUMNS} for row in read_table(path / TABLE_FILE)]


def test_dask_cluster_gives_the_same_table_as_the_local_pool(tmp_path, scheduler):
    vary = ["clearance_mm=0.1,0.2,0.3", "speed_rpm=300:600:4", "restitution=0.2,0.9"]  # 0.2: fake engine raises
    plan = plan_sweep(REFERENCE, vary, ["revolutions=0.5"], "test_sweep:fake_solve")
    local = run_sweep(plan, tmp_path / "local", jobs=2, progress=False)
    remote = run_sweep(plan, tmp_path / "dask", scheduler=scheduler, progress=False)
    assert (remote.succeeded, remote.failed) == (local.succeeded, local.failed) == (12, 12)
    assert _table(tmp_path / "dask") == _table(tmp_path / "local")
    # Resume works the same way through the cluster: nothing is run twice.
    again = run_sweep(plan, tmp_path / "dask", scheduler=scheduler, progress=False)
    assert (again.skipped, again.succeeded) == (12, 0)


def test_reference_engine_cells_on_the_cluster_match_the_local_pool(tmp_path, scheduler):
    args = ["sweep", str(REFERENCE), "--vary", "clearance_mm=0.1,0.25", "--set", "revolutions=0.25"]
    assert main([*args, "-o", str(tmp_path / "local"), "--jobs", "2"]) == 0
    assert main([*args, "-o", str(tmp_path / "dask"), "--scheduler", scheduler]) == 0
    rows = _table(tmp_path / "dask")
    assert [r["status"] for r in rows] == ["success", "success"]
    # Same deterministic engine, same machine: identical to the last printed digit.
    assert rows == _table(tmp_path / "local")
    assert float(rows[0]["rapier_acceleration_m_s2_rev1_peak"]) > 0
    # A cluster's worker was not started by this command: every cell still records the sweep's command line.
    for row in rows:
        command = json.loads((tmp_path / "dask" / row["cell"] / MANIFEST).read_text())["command"]
        assert command.startswith("weftsim sweep ") and command.endswith(scheduler), command


def test_workers_in_another_directory_without_the_sweep_directory(tmp_path, scheduler, monkeypatch):
    """A relative scene path and a relative sweep directory, as a user types them: the workers stand in
    another directory and cannot see the client's files, yet every cell runs and its files (error.txt of a
    failed cell too) arrive in the client's sweep directory."""
    client_dir = tmp_path / "client"
    client_dir.mkdir()
    shutil.copy(REFERENCE, client_dir / "scene.toml")
    monkeypatch.chdir(client_dir)
    status = main(["sweep", "scene.toml", "--vary", "clearance_mm=0.1,0.2,0.3", "--vary", "restitution=0.2,0.9",
                   "--set", "revolutions=0.5", "--engine", FAKE, "--scheduler", scheduler, "-o", "sweep"])
    assert status == EXIT_FAILED  # restitution 0.2: the fake engine raises (3 cells)
    rows = read_table(client_dir / "sweep" / TABLE_FILE)
    assert [r["status"] for r in rows].count("success") == 3 and len(rows) == 6
    for row in rows:
        cell = client_dir / "sweep" / row["cell"]
        # A cell whose engine raised has no run to write: its record and the error with the traceback.
        expected = ["cell.json", "error.txt"] if row["status"] == "failed" else ["cell.json", "channels.csv",
                                                                                "scene.toml", "summary.json"]
        assert sorted(p.name for p in cell.iterdir() if not p.name.startswith(".")) == sorted(expected)
        assert read_record(cell)["worker"]["pid"] != os.getpid()
    with distributed.Client(scheduler) as client:
        assert all(blocked == [] for blocked in client.run(_blocked).values())


def test_killing_the_client_loses_nothing_the_cluster_returned(tmp_path):
    """SIGKILL the sweep's client mid-sweep: every cell it had received is on disk and finished; the same
    command resumes without redoing them."""
    cluster, elsewhere = blind_cluster(tmp_path, env={"WEFTSIM_FAKE_DELAY_S": "0.3"})
    outdir = tmp_path / "s"
    with cluster:
        command = [sys.executable, "-m", "weftsim.cli", "sweep", str(REFERENCE), "--vary",
                   "clearance_mm=0.1,0.2,0.3", "--vary", "speed_rpm=300:600:4", "--set", "revolutions=0.5",
                   "--engine", FAKE, "--scheduler", cluster.scheduler_address, "-o", str(outdir)]
        env = {**os.environ, "PYTHONPATH": str(ROOT / "tests")}
        client = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 120  # a loaded 2-core machine; 12 cells of 0.3 s normally take ~2 s
        while len(list(outdir.glob(f"*/{CELL_FILE}"))) < 3:
            assert client.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        client.kill()
        client.wait()
        finished = sorted(p.parent for p in outdir.glob(f"*/{CELL_FILE}"))
        assert 3 <= len(finished) < 12
        for cell in finished:
            assert is_finished(cell, read_record(cell)["scene"], FAKE)
        before = {p: p.stat().st_mtime_ns for d in finished for p in d.iterdir()}
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=180)
        assert done.returncode == 0, done.stderr
        assert f"{len(finished)} already finished, {12 - len(finished)} succeeded" in done.stdout
        assert all(p.stat().st_mtime_ns == t for p, t in before.items())
        assert {r["status"] for r in read_table(outdir / TABLE_FILE)} == {"success"}
        check_workers_stayed_blind(cluster.scheduler_address, elsewhere)
    shutil.rmtree(elsewhere, ignore_errors=True)


def test_unreachable_scheduler_is_one_clear_error(tmp_path, capsys, monkeypatch):
    # Port 9 (discard) on loopback: nothing listens there; Dask retries until the timeout, cut to 1 s here.
    monkeypatch.setattr("weftsim.sweep.pool.CONNECT_TIMEOUT_S", 1.0)
    status = main(["sweep", str(REFERENCE), "--vary", "clearance_mm=0.1", "--set", "revolutions=0.25",
                   "-o", str(tmp_path), "--scheduler", "tcp://127.0.0.1:9"])
    assert status == 2
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in capsys.readouterr().err
