"""A regular (non-editable) install carries the bundled scenes: the wheel holds models/ as weftsim/scenes."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_wheel_holds_every_scene_file_and_the_type_marker(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    for name in ("weftsim", "models"):
        shutil.copytree(ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    # As `pip install .` builds it: in an isolated build environment with pyproject.toml's build requirements.
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp_path / "dist"),
                           str(source)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    (wheel,) = (tmp_path / "dist").glob("weftsim-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    scenes = {f"weftsim/scenes/{p.relative_to(ROOT / 'models').as_posix()}" for p in (ROOT / "models").rglob("*.toml")}
    assert scenes and scenes <= names, sorted(scenes - names)
    assert "weftsim/py.typed" in names and "weftsim/api.py" in names
    assert "weftsim/physics/film_table.npz" in names  # the finite journal bearing's table (physics/film.py)
    assert not any(name.startswith("models/") for name in names)  # inside the package, not a top-level folder
