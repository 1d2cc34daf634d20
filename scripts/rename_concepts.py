"""Rename two subpackages to the concept they hold (issue 32), and every reference to them.

    weftsim/kernel/  ->  weftsim/physics/   the physics, written once, compiled (contact laws, chain, film, wear)
    weftsim/run/     ->  weftsim/checks/    before-run checks, guards, post-run vetting, estimates

Run from the repository root, on a clean work tree::

    .venv/bin/python scripts/rename_concepts.py          # git mv, rewrite, check
    .venv/bin/python scripts/rename_concepts.py --check  # only check that no old path is left

What it does, in order (a second run changes nothing and says so):

1. ``git mv`` of each old directory's tracked files into the new one (git's rename detection then carries
   another branch's edits of a moved file through a merge); a file another branch added to the old
   directory after the first run (a merged tree) is moved the same way.
2. Rewrites every reference in the tracked text files (code, tests, scripts, examples, docs, README,
   pyproject.toml's package data, monkeypatch strings): the dotted module names ``weftsim.kernel`` /
   ``weftsim.run`` (as a word, so ``weftsim.running`` is left alone), the paths ``weftsim/kernel/``,
   ``weftsim/run/`` and, in docs and docstrings, ``kernel/NAME.py`` / ``run/NAME.py``, and the floor and
   concept names of scripts/house.py and tests/test_imports.py.  CHANGELOG.md is history and is left as it
   was (its new entry names the rename).
3. Checks: no old reference is left in a tracked file, and every ``weftsim`` module imports in a fresh
   interpreter (each of ``weftsim.*`` found in the tree, by ``importlib``), so a reference the rewrite
   missed is found here rather than by a user.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RENAMES = {"kernel": "physics", "run": "checks"}
LEFT_AS_IS = {"CHANGELOG.md", "scripts/rename_concepts.py"}  # history, and this script's own table
TEXT = (".py", ".md", ".rst", ".toml", ".txt", ".cfg", ".ini", ".sh", ".yml", ".yaml", ".json", "")


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True, text=True).stdout


def _tracked() -> list[Path]:
    return [ROOT / p for p in _git("ls-files").splitlines()]


def move() -> int:
    """git mv every tracked file of an old directory into the new one; the number moved."""
    moved = 0
    for old, new in RENAMES.items():
        for path in _git("ls-files", f"weftsim/{old}").splitlines():
            target = Path(path.replace(f"weftsim/{old}/", f"weftsim/{new}/", 1))
            (ROOT / target).parent.mkdir(parents=True, exist_ok=True)
            _git("mv", path, str(target))
            moved += 1
        stale = ROOT / "weftsim" / old
        if stale.is_dir() and not any(p.is_file() and "__pycache__" not in p.parts for p in stale.rglob("*")):
            for cache in sorted(stale.rglob("*"), reverse=True):  # what is left is numba's and Python's caches
                cache.unlink() if cache.is_file() else cache.rmdir()
            stale.rmdir()
    return moved


def patterns() -> list[tuple[re.Pattern, str]]:
    out = []
    for old, new in RENAMES.items():
        out += [
            (re.compile(rf"\bweftsim\.{old}\b(?!\w)"), f"weftsim.{new}"),
            (re.compile(rf"\bweftsim/{old}/"), f"weftsim/{new}/"),
            (re.compile(rf"\bweftsim/{old}\b(?![\w.])"), f"weftsim/{new}"),
            # a module path written from inside the package (docs tables, docstrings): kernel/chain.py
            (re.compile(rf"(?<![\w/.-]){old}/(\w+\.(?:py|npz))"), rf"{new}/\1"),
            # `from weftsim import kernel` / `from weftsim import run` (a subpackage imported by its name)
            (re.compile(rf"(from weftsim import (?:[\w ,]*, )?){old}\b"), rf"\g<1>{new}"),
        ]
    return out


# The subpackages' names as words in the two files that list the floors and the concepts.
NAMED = {"scripts/house.py": [(rf'"{old}": ', f'"{new}": ') for old, new in RENAMES.items()]
         + [(rf"``{old}``", f"``{new}``") for old, new in RENAMES.items()],
         "tests/test_imports.py": [(r'"run", "post"', '"checks", "post"')]}


def rewrite() -> list[str]:
    """Rewrite the references (module docstring); the files changed."""
    changed = []
    rules = patterns()
    for path in _tracked():
        rel = path.relative_to(ROOT).as_posix()
        if rel in LEFT_AS_IS or path.suffix not in TEXT or not path.is_file():
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        new = text
        for rule, repl in rules:
            new = rule.sub(repl, new)
        for old, repl in NAMED.get(rel, []):
            new = re.sub(old, repl, new)
        if new != text:
            path.write_text(new, encoding="utf-8")
            changed.append(rel)
    return changed


def leftovers() -> list[str]:
    """Tracked places that still name an old subpackage."""
    found = []
    for path in _tracked():
        rel = path.relative_to(ROOT).as_posix()
        if rel in LEFT_AS_IS or path.suffix not in TEXT or not path.is_file():
            continue
        if any(rel.startswith(f"weftsim/{old}/") for old in RENAMES):
            found.append(f"{rel}: still in the old directory")
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for rule, _ in patterns():
            for match in rule.finditer(text):
                line = text.count("\n", 0, match.start()) + 1
                found.append(f"{rel}:{line}: {match.group(0)}")
    return found


def imports_resolve() -> list[str]:
    """Every weftsim module of the tree imported in a fresh interpreter; the failures, one line each."""
    names = []
    for path in sorted((ROOT / "weftsim").rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__main__":
            continue
        names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    probe = ("import importlib, sys\nbad = []\nfor n in sys.argv[1:]:\n    try:\n        importlib.import_module(n)\n"
             "    except Exception as e:\n        bad.append(f'{n}: {type(e).__name__}: {e}')\nprint('\\n'.join(bad))\n")
    done = subprocess.run([sys.executable, "-c", probe, *names], cwd=ROOT, capture_output=True, text=True)
    return [line for line in done.stdout.splitlines() if line] + ([done.stderr] if done.returncode else [])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only check (no move, no rewrite)")
    args = parser.parse_args(argv)
    if not args.check:
        moved, changed = move(), rewrite()
        print(f"moved {moved} files, rewrote {len(changed)} files" if moved or changed else
              "nothing to rename: the tree already uses the new names")
    left = leftovers()
    for line in left:
        print(f"old name left: {line}")
    failed = imports_resolve()
    for line in failed:
        print(f"does not import: {line}")
    if left or failed:
        return 1
    print(f"no old path left; every weftsim module imports ({', '.join(f'{o} -> {n}' for o, n in RENAMES.items())})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
