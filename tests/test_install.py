"""The lock file (requirements.lock) and the bounds of pyproject.toml agree: every dependency is pinned
to one public release, inside the range the package declares, so the lock installs what was tested."""

import re
import tomllib
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]
PINNED = re.compile(r"^(?P<name>[A-Za-z0-9][A-Za-z0-9._-]*)==(?P<version>[0-9][0-9A-Za-z.!-]*)$")


def lock() -> dict[str, Version]:
    """Package name (canonical) -> pinned version, from requirements.lock."""
    pins = {}
    for line in (ROOT / "requirements.lock").read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        match = PINNED.match(line)
        assert match, f"requirements.lock: not 'name==version' of a public release: {line!r}"
        name = canonicalize_name(match["name"])
        assert name not in pins, f"requirements.lock pins {name} twice"
        pins[name] = Version(match["version"])
    return pins


def declared() -> list[Requirement]:
    """The run-time dependencies and those of the [test] and [docs] extras (what CI installs), as
    pyproject.toml states them."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    return [Requirement(text) for text in project["dependencies"] + extras["test"] + extras["docs"]]


def test_lock_pins_public_releases_and_not_weftsim_itself():
    pins = lock()  # every line name==version: no path, URL or "+local" build that no index serves
    assert "weftsim" not in pins  # installed from the working tree, never from the lock


def test_lock_holds_every_package_its_packages_need():
    """Closed under requirements (on this Python and platform, with the extras weftsim asks for), so a
    fresh install resolves nothing unpinned.  Read from the metadata of the installed packages; those
    installed at another version than the lock's (an environment not made from it) are passed over."""
    pins = lock()
    todo = [(canonicalize_name(r.name), frozenset(r.extras)) for r in declared()]
    seen, checked, missing = set(), 0, []
    while todo:
        name, extras = todo.pop()
        if (name, extras) in seen or name not in pins:
            continue
        seen.add((name, extras))
        try:
            dist = metadata.distribution(name)
        except metadata.PackageNotFoundError:
            continue
        if Version(dist.version) != pins[name]:
            continue
        checked += 1
        for requirement in map(Requirement, dist.requires or []):
            if requirement.marker and not any(requirement.marker.evaluate({"extra": e}) for e in extras | {""}):
                continue
            needed = canonicalize_name(requirement.name)
            if needed not in pins:
                missing.append(f"{name} needs {requirement}")
            todo.append((needed, frozenset(requirement.extras)))
    if not checked:
        pytest.skip("no package of requirements.lock is installed at its pinned version")
    assert not missing, f"requirements.lock lacks: {missing}; run scripts/refresh_lock.sh"


def test_every_declared_dependency_is_pinned_inside_its_declared_range():
    pins = lock()
    for requirement in declared():
        name = canonicalize_name(requirement.name)
        assert name in pins, f"{requirement} is not pinned in requirements.lock: run scripts/refresh_lock.sh"
        assert pins[name] in requirement.specifier, f"requirements.lock pins {name}=={pins[name]}, outside {requirement}"


def test_every_run_time_dependency_has_an_upper_bound_or_a_pin():
    """A new major release (numpy 3, scipy 2) must not reach a user's installation untested."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    runtime = [Requirement(text) for text in project["dependencies"]]
    open_ended = [str(r) for r in runtime if not any(s.operator in ("<", "<=", "==", "~=") for s in r.specifier)]
    assert not open_ended, f"pyproject.toml dependencies without an upper bound: {open_ended}"
