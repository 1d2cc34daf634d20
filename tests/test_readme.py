"""The README stays true to the code: its scene reference lists every key, its quick start matches CI."""

from pathlib import Path

import pytest

from weftsim.scene import SCHEMA

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
