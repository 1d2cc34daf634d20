"""The README stays true to the code: its scene reference lists every key, its quick start matches CI."""

from pathlib import Path

import pytest

from weftsim.input.scene import SCHEMA

ROOT = Path(__file__).resolve().parents[1]


def test_readme_lists_every_scene_key():
    readme = (ROOT / "README.md").read_text()
    missing = [key.path for key in SCHEMA if f"`{key.path}`" not in readme]
    assert not missing, f"README scene reference lacks {missing}: regenerate with scripts/scene_reference.py"


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text()
    ci = (ROOT / ".ci" / "run").read_text()
    command = "python3 -m venv .venv && .venv/bin/pip install -q -c requirements.lock '.[test]' && .venv/bin/pytest -q"
    assert command in readme and command in ci


def test_every_install_command_of_the_readme_and_ci_uses_the_lock():
    """A quick start that installs unpinned packages would test other versions than CI does."""
    for name in ("README.md", ".ci/run"):
        installs = [line for line in (ROOT / name).read_text().splitlines() if "pip install" in line and "&&" in line]
        assert installs, f"{name} has no install command"
        unlocked = [line for line in installs if "-c requirements.lock" not in line]
        assert not unlocked, f"{name} installs without the lock: {unlocked}"


def _block(readme: str, language: str, after: str) -> str:
    """The first fenced ``language`` block after the line ``after``."""
    start = readme.index(after)
    fence = f"```{language}\n"
    begin = readme.index(fence, start) + len(fence)
    return readme[begin:readme.index("```", begin)]


def test_the_quick_start_runs_a_bundled_scene():
    """The README's main job is the bundled loom (issue 21); the paper comparison stays on `reference`."""
    readme = (ROOT / "README.md").read_text()
    command = _block(readme, "bash", "## Quick start")
    assert command.strip().endswith(".venv/bin/weftsim run loom")


def test_the_readme_script_simulates_both_engines_into_pandas_tables(capsys):
    """The README's ten-line script, run as written: both engines, a table each, printed results."""
    pandas = pytest.importorskip("pandas")
    script = _block((ROOT / "README.md").read_text(), "python", "## Python")
    assert len(script.strip().splitlines()) <= 10
    namespace: dict = {}
    exec(compile(script, "README.md", "exec"), namespace)
    tables = namespace["tables"]
    assert set(tables) == {"reference", "exudyn"}
    for table in tables.values():
        assert isinstance(table, pandas.DataFrame) and "contact_force_N" in table.columns
        # One revolution on the 0.5 deg output grid: 720 intervals, 721 samples.
        assert len(table) == 721
        assert table["contact_force_N"].max() > 0  # c = 0.5 mm: the journal hits the bearing
    printed = capsys.readouterr().out
    assert "reference success" in printed and "exudyn success" in printed


DOCS_COMMAND = "python3 -m venv .venv && .venv/bin/pip install -q -c requirements.lock '.[docs]' && scripts/build_docs.sh"


def test_the_readme_docs_command_is_the_one_ci_runs():
    """Issue 25: the docs build as the README says; CI builds them with the README's command, verbatim."""
    readme = (ROOT / "README.md").read_text()
    command = _block(readme, "bash", "Build the documentation site").strip()
    assert command == DOCS_COMMAND
    assert command in (ROOT / ".ci" / "run").read_text()


def _fake_python(path: Path, log: Path) -> None:
    """An executable standing in for a Python: it records that it ran, with its arguments, and succeeds."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'#!/bin/sh\necho "{path.name} $*" >> "{log}"\n')
    path.chmod(0o755)


def _run_build_docs(tmp_path: Path, env_python: str | None, with_venv: bool) -> list[str]:
    """Run a copy of scripts/build_docs.sh in a scratch checkout whose Pythons only record their calls."""
    import os
    import shutil
    import subprocess

    checkout = tmp_path / "checkout"
    (checkout / "scripts").mkdir(parents=True)
    shutil.copy2(ROOT / "scripts" / "build_docs.sh", checkout / "scripts" / "build_docs.sh")
    log = tmp_path / "calls.log"
    log.touch()
    if with_venv:
        _fake_python(checkout / ".venv" / "bin" / "python", log)
    bindir = tmp_path / "bin"
    _fake_python(bindir / "python3", log)  # the python3 on PATH
    env = {k: v for k, v in os.environ.items() if k != "PYTHON"}
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"
    if env_python:
        env["PYTHON"] = env_python
    done = subprocess.run(["bash", str(checkout / "scripts" / "build_docs.sh"), "-D", "plot_gallery=0"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return log.read_text().splitlines()


def test_build_docs_uses_the_checkout_venv_that_the_readme_command_makes(tmp_path):
    """The README's command installs the docs extra into .venv: the script must build with that Python
    (issue 25: it ran python3 and stopped), checking the extra and running sphinx-build, arguments passed on."""
    calls = _run_build_docs(tmp_path, None, with_venv=True)
    assert len(calls) == 4 and all(call.startswith("python ") for call in calls), calls
    assert "import sphinx" in calls[0]
    assert calls[1].startswith("python -m sphinx -W") and calls[1].endswith("-D plot_gallery=0")
    assert calls[2] == "python scripts/check_anchors.py docs/_build/html"
    assert calls[3] == "python scripts/check_offline_math.py docs/_build/html"  # the equations show offline


def test_build_docs_falls_back_to_python3_and_obeys_PYTHON(tmp_path):
    calls = _run_build_docs(tmp_path / "bare", None, with_venv=False)
    assert [call.split()[0] for call in calls] == ["python3"] * 4
    chosen = tmp_path / "chosen" / "python"
    _fake_python(chosen, tmp_path / "chosen.log")
    (tmp_path / "chosen.log").touch()
    _run_build_docs(tmp_path / "env", str(chosen), with_venv=True)
    assert len((tmp_path / "chosen.log").read_text().splitlines()) == 4
    assert not (tmp_path / "env" / "calls.log").read_text()  # neither .venv's nor PATH's python ran


def test_the_docs_extra_covers_what_the_gallery_needs():
    """The README's docs command installs '.[docs]' only: every optional package an example reaches (through
    weftsim.load_sweep or RunResult.to_pandas) must be in that extra, or the gallery stops on a fresh clone
    (it did: plot_sweep_grid.py needs xarray)."""
    import re
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    docs = {re.split(r"[<>=\[ ]", requirement, maxsplit=1)[0] for requirement in extras["docs"]}
    needs = {"load_sweep": {"xarray"}, "to_pandas": {"pandas"}, "import dask": {"dask"}}
    for example in sorted((ROOT / "examples").glob("plot_*.py")):
        text = example.read_text()
        for call, packages in needs.items():
            if call in text:
                assert packages <= docs, f"{example.name} uses {call}: the docs extra lacks {packages - docs}"


def test_check_anchors_finds_a_link_to_a_missing_id(tmp_path):
    """scripts/check_anchors.py (run by build_docs.sh): a link to an id its page lacks fails the build."""
    import subprocess
    import sys

    (tmp_path / "api").mkdir()
    (tmp_path / "api" / "simulate.html").write_text('<h1 id="weftsim.simulate">simulate</h1><a href="#top">x</a>')
    (tmp_path / "index.html").write_text('<p id="top"></p><a href="api/simulate.html#weftsim.simulate">ok</a>'
                                         '<a href="https://numpy.org/doc/#external">not ours</a>')
    script = ROOT / "scripts" / "check_anchors.py"
    ok = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True)
    assert ok.returncode == 1 and "api/simulate.html: link to a missing anchor: #top" in ok.stderr
    (tmp_path / "api" / "simulate.html").write_text('<h1 id="weftsim.simulate">simulate</h1><a href="../index.html#top">x</a>')
    ok = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
