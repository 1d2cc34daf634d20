"""Output files are atomic and never silently mixed with files of another run."""

import json

import numpy as np
import pytest

from weftsim.post.output import MANIFEST, OutputError, finish_directory, prepare_directory, write_atomic, write_csv


def test_failed_write_keeps_the_previous_complete_file(tmp_path):
    target = tmp_path / "channels.csv"
    write_csv(target, {"time_s": np.arange(3.0)})
    before = target.read_text()

    def dies_half_way(path):
        path.write_text("time_s\n0\n")
        raise RuntimeError("killed")

    with pytest.raises(RuntimeError):
        write_atomic(target, dies_half_way)
    assert target.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["channels.csv"]  # no temporary file left behind


def test_foreign_directory_is_refused_unless_forced(tmp_path):
    (tmp_path / "thesis.tex").write_text("mine")
    with pytest.raises(OutputError, match="not written by weftsim"):
        prepare_directory(tmp_path)
    assert prepare_directory(tmp_path, force=True) == tmp_path


def test_rerun_removes_stale_files_of_the_previous_run(tmp_path):
    out = prepare_directory(tmp_path / "run")
    a = write_csv(out / "a.csv", {"x": np.zeros(2)})
    b = write_csv(out / "b.png", {"x": np.zeros(2)})
    finish_directory(out, {"a": a, "b": b}, {"kind": "test"})
    prepare_directory(out)  # ours now: accepted
    a = write_csv(out / "a.csv", {"x": np.ones(2)})
    finish_directory(out, {"a": a}, {"kind": "test"})
    assert sorted(p.name for p in out.iterdir()) == sorted([MANIFEST, "a.csv"])
    assert json.loads((out / MANIFEST).read_text())["files"] == ["a.csv"]
