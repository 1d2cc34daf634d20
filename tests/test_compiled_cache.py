"""The compiled physics is cached in a folder keyed by its source (weftsim.physics.compiled_cache).

numba's own cache checks only the defining file's time stamp: a kernel compiled against another module's
parameter indices was loaded stale after those indices changed (a worn reference run reported a penetration
of 675 mm at t = 2e-14 s).  These tests check the key and that every cached kernel of weftsim uses it."""

import importlib
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import weftsim
from weftsim.physics.compiled_cache import cache_folder, source_digest


def test_every_cached_kernel_of_weftsim_lives_in_the_keyed_folder():
    """Import every module that compiles with cache=True; each dispatcher's cache path is in the keyed folder
    (a module decorating before the physics set the folder would fall back to numba's unkeyed cache)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        pytest.skip("NUMBA_CACHE_DIR set by the user: numba's folder is theirs")
    from numba.core.registry import CPUDispatcher

    folder = str(cache_folder())
    seen = 0
    for info in pkgutil.walk_packages(weftsim.__path__, "weftsim."):
        path = Path(importlib.util.find_spec(info.name).origin)
        if "cache=True" not in path.read_text():
            continue
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher) and value._cache is not None and value.__module__ == info.name:
                assert value._cache._cache_path.startswith(folder), (info.name, value.__name__)
                seen += 1
    assert seen > 50  # the physics, the chains, the integrators (about 200 when written)


def test_a_change_to_any_compiled_module_changes_the_folder(tmp_path):
    """The digest covers every module that uses numba, and only those."""
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "a.py").write_text("from numba import njit\nINDEX = 3\n")
    (package / "sub" / "b.py").write_text("from numba import njit\n")
    (package / "c.py").write_text("x = 1\n")
    before = source_digest(package)
    (package / "c.py").write_text("x = 2\n")  # no numba: no recompilation for it
    assert source_digest(package) == before
    (package / "a.py").write_text("from numba import njit\nINDEX = 4\n")  # an index another kernel reads
    assert source_digest(package) != before


def test_a_user_cache_dir_wins(tmp_path):
    code = "import weftsim.physics.joint, numba.core.config as c; print(c.CACHE_DIR)"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == str(tmp_path)
