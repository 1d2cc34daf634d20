"""The README stays true to the code: its scene reference lists every key, its quick start matches CI."""

from pathlib import Path

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
