"""What a result says about where it came from: versions, commit, ``weftsim --version``, package files."""

from __future__ import annotations

import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

from weftsim.post.analysis import summary
from conftest import door
solve = door("reference")
from weftsim.input.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]


def test_the_summary_records_the_versions_and_the_commit():
    result = solve(load_scene(ROOT / "models" / "reference.toml", {"drive.revolutions": 0.02}))
    s = summary(result)
    for name in ("weftsim", "exudyn", "numpy", "scipy", "numba", "matplotlib"):
        assert s["versions"][name] == metadata.version(name), name
    assert s["versions"]["python"] == ".".join(map(str, sys.version_info[:3]))
    # A git checkout (as here and in CI) gives its HEAD, "+dirty" with local changes; an installed wheel None.
    assert s["commit"] is None or re.fullmatch(r"[0-9a-f]{40}(\+dirty)?", s["commit"]), s["commit"]


def test_version_flag_prints_one_line_and_exits_0():
    done = subprocess.run([sys.executable, "-m", "weftsim.cli", "--version"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"weftsim {metadata.version('weftsim')} (Python ")
    assert f"numpy {metadata.version('numpy')}" in lines[0] and f"exudyn {metadata.version('exudyn')}" in lines[0]


def test_the_package_ships_its_typing_marker_and_the_repository_its_license():
    assert (ROOT / "weftsim" / "py.typed").is_file()
    assert "weftsim" in (ROOT / "pyproject.toml").read_text().split("[tool.setuptools.package-data]")[1]
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")  # pyproject.toml says MIT
