"""The distributed path: the same cells on a Dask LocalCluster give the same table as the local pool.

The cluster is started by the test on the loopback interface (two worker processes, one
thread each) and closed at the end; the sweep reaches it through ``--scheduler``.
"""

from pathlib import Path

import pytest

from weftsim.cli import main
from weftsim.sweep import plan_sweep, run_sweep
from weftsim.sweep.store import TABLE_FILE, read_table

distributed = pytest.importorskip("dask.distributed")

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "models" / "reference.toml"
TIMING_COLUMNS = ("wall_time_s",)  # the only columns allowed to differ between two runs of the same cells


@pytest.fixture(scope="module")
def scheduler():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        yield cluster.scheduler_address


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


def test_unreachable_scheduler_is_one_clear_error(tmp_path, capsys, monkeypatch):
    # Port 9 (discard) on loopback: nothing listens there; Dask retries until the timeout, cut to 1 s here.
    monkeypatch.setattr("weftsim.sweep.pool.CONNECT_TIMEOUT_S", 1.0)
    status = main(["sweep", str(REFERENCE), "--vary", "clearance_mm=0.1", "--set", "revolutions=0.25",
                   "-o", str(tmp_path), "--scheduler", "tcp://127.0.0.1:9"])
    assert status == 2
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in capsys.readouterr().err
