"""The house: how weftsim's modules depend on one another, and the walk of one scene into each engine.

Run from the repository root::

    .venv/bin/python scripts/house.py            # the figures, one line each
    .venv/bin/python scripts/house.py --list     # and every arrow back up, every circle
    .venv/bin/python scripts/house.py --no-walk  # the static figures only (no simulation)

The figures (issue 32), all read from the source with :mod:`ast` except the walk:

- **circles**: strongly connected components of more than one module in the graph of every weftsim
  import (module level, under ``if TYPE_CHECKING:`` and inside functions; a package's ``__init__``
  importing its own submodules is how it exports them, not an edge);
- **internal imports**: the import statements naming a weftsim module, and how many of them sit inside
  a function (deferred imports hide dependencies from a reader of the module's head);
- **arrows back up**: distinct (importer, imported) module pairs, of the same graph without the
  ``TYPE_CHECKING`` imports (annotations only), where the importer sits on a lower floor than the module it
  imports (:data:`FLOORS`);
- **the walk** of one scene into each engine: ``weftsim.simulate(scene, engine)`` on a loaded scene,
  traced with :func:`sys.setprofile`.  The walk is the sequence of weftsim functions in the order of
  their *first* call (a function called again in a loop of the integrator is one step of the walk, so
  the figures say how the code is laid out, not how many steps a run takes); import-time module code is
  left out.  *files*: distinct files the walk enters; *stays*: maximal runs of consecutive walk entries in
  one file; *climbs*: distinct (caller, callee) function pairs of those first calls where the caller's file
  sits on a lower floor than the callee's; *other engine*: functions of the other engine's package the walk
  calls (the Exudyn engine's walk entering ``weftsim/reference/`` means it depends on the reference engine).

The floors, from the bottom (a module may import its own floor and the floors below it):

0. ``errors``, ``version``: what every module raises and reports;
1. ``physics``: the physics, compiled (contact laws, the chain's equations, the film, wear);
2. ``input``: the scene as validated, frozen SI data (``Scene``);
3. ``joint``, ``mechanism``, ``model``: the clearance joint, the linkage's kinematics, the shared model
   both engines build on (parameter packing, initial state, crank-side inertia and potential);
4. ``checks``: before-run checks, guards, post-run vetting, estimates;
5. ``post``: results (``RunResult``), analysis, output files, the figures and comparison reports that show
   the checks of ``checks`` (so ``post`` sits above ``checks``; the checks reading a result's channel table,
   ``weftsim.checks.plausibility`` -> ``weftsim.post.results``, is the one arrow back up between them);
6. ``reference``, ``exudyn_engine``: the two engines (neither imports the other);
7. ``engines``: the registry that names the engines, and ``simulate``, the one door into them;
8. ``sweep``, ``studies``, ``wear``, ``bench``, ``optimize``: what runs many simulations through the door;
9. ``api``: the Python interface (``simulate`` re-exported, ``sweep``, ``wear``, ``compare``, ...);
10. ``cli``, ``__main__``, the package ``__init__``: the command line and the package's exports.

(Before issue 32 there was no ``engines`` module and no ``model`` subpackage; the same floors apply to the
tree before it.)

The same script measured the house before and after issue 32 (its figures are in CHANGELOG.md).
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "weftsim"

FLOORS: dict[str, int] = {
    "errors": 0, "version": 0,
    "physics": 1,
    "input": 2,
    "joint": 3, "mechanism": 3, "model": 3,
    "checks": 4,
    "post": 5,
    "reference": 6, "exudyn_engine": 6,
    "engines": 7,
    "sweep": 8, "studies": 8, "wear": 8, "bench": 8, "optimize": 8,
    "api": 9,
    "cli": 10, "__main__": 10, "": 10,  # "" is the package's __init__
}


def modules() -> dict[str, Path]:
    """Dotted module name -> file, for every module of the package."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def floor(module: str) -> int:
    """The floor of a dotted weftsim module (:data:`FLOORS`); an unknown subpackage is an error."""
    part = module.split(".")[1] if "." in module else ""
    if part not in FLOORS:
        raise SystemExit(f"house.py: {module} is in no floor; add its subpackage {part!r} to FLOORS")
    return FLOORS[part]


def _resolve(name: str, known: dict[str, Path]) -> str | None:
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def _type_checking(node: ast.AST) -> bool:
    if not isinstance(node, ast.If):
        return False
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imports() -> list[dict]:
    """Every import statement naming a weftsim module: importer, targets, where (module/function/typing)."""
    known = modules()
    found = []

    def visit(node: ast.AST, name: str, package: str, where: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = where
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                inner = "function"
            elif _type_checking(child) and where == "module":
                inner = "typing"
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                if isinstance(child, ast.Import):
                    targets = [a.name for a in child.names]
                else:
                    base = child.module or ""
                    if child.level:
                        parts = package.split(".")[: len(package.split(".")) - child.level + 1]
                        base = ".".join(parts + ([base] if base else []))
                    targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in child.names]
                edges = {_resolve(t, known) for t in targets if t == "weftsim" or t.startswith("weftsim.")}
                own = known[name].name == "__init__.py"
                edges = {e for e in edges if e and e != name and not (own and e.startswith(name + "."))}
                if edges:
                    found.append({"importer": name, "targets": sorted(edges), "where": where, "line": child.lineno})
            visit(child, name, package, inner)

    for name, path in known.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        visit(ast.parse(path.read_text(encoding="utf-8")), name, package, "module")
    return found


def graph(with_typing: bool = True) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {name: set() for name in modules()}
    for row in imports():
        if with_typing or row["where"] != "typing":
            out[row["importer"]].update(row["targets"])
    return out


def circles(g: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found = []
    for root in sorted(g):
        if root in index:
            continue
        work = [(root, iter(sorted(g[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(g.get(w, ())))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        found.append(sorted(comp))
    return found


def arrows_up() -> list[tuple[str, str]]:
    """(importer, imported) pairs running from a lower floor to a higher one (TYPE_CHECKING left out)."""
    return sorted((a, b) for a, targets in graph(with_typing=False).items() for b in targets if floor(a) < floor(b))


def walk(scene_name: str, engine: str) -> dict:
    """Trace ``weftsim.simulate`` of a loaded scene on ``engine`` (module docstring): files, stays, climbs."""
    import weftsim

    scene = weftsim.load_scene(scene_name)
    weftsim.simulate(scene, engine, on_warning=lambda text: None)  # warm: imports and compiled code
    package = str(PACKAGE)
    first: list[tuple[str, str]] = []
    seen: set = set()
    pairs: set = set()

    def module_of(filename: str) -> str:
        rel = Path(filename).resolve().relative_to(ROOT).with_suffix("")
        parts = rel.parts
        return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)

    def profile(frame, event, arg):
        if event != "call":
            return
        code = frame.f_code
        if not code.co_filename.startswith(package) or code.co_name == "<module>":
            return
        if code not in seen:
            seen.add(code)
            first.append((code.co_filename, code.co_name))
            caller = frame.f_back
            if caller is not None and caller.f_code.co_filename.startswith(package):
                pairs.add((caller.f_code, code))

    sys.setprofile(profile)
    try:
        weftsim.simulate(scene, engine, on_warning=lambda text: None)
    finally:
        sys.setprofile(None)
    files = [f for f, _ in first]
    stays = sum(1 for i, f in enumerate(files) if i == 0 or files[i - 1] != f)
    climbs = sorted((module_of(a.co_filename), a.co_name, module_of(b.co_filename), b.co_name) for a, b in pairs
                    if floor(module_of(a.co_filename)) < floor(module_of(b.co_filename)))
    other = str(PACKAGE / ("reference" if engine == "exudyn" else "exudyn_engine"))
    return {"scene": scene_name, "engine": engine, "functions": len(first), "files": len(set(files)),
            "stays": stays, "climbs": len(climbs), "climb_list": climbs,
            "other_engine": sum(1 for f in files if f.startswith(other + "/"))}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="list every arrow back up, circle and climb")
    parser.add_argument("--no-walk", action="store_true", help="skip the traced walks (no simulation)")
    parser.add_argument("--scene", default="reference", help="the scene walked into each engine")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    rows = imports()
    inside = sum(1 for r in rows if r["where"] == "function")
    found = circles(graph())
    up = arrows_up()
    print(f"circles: {len(found)}")
    print(f"internal imports: {len(rows)} statements, {inside} inside functions")
    print(f"arrows back up a floor: {len(up)}")
    if args.list:
        for comp in found:
            print("  circle:", " -> ".join(comp))
        for a, b in up:
            print(f"  up: {a} (floor {floor(a)}) -> {b} (floor {floor(b)})")
    if not args.no_walk:
        for engine in ("reference", "exudyn"):
            w = walk(args.scene, engine)
            print(f"walk of {w['scene']} into {engine}: {w['functions']} functions, {w['files']} files, "
                  f"{w['stays']} stays, {w['climbs']} climbs, {w['other_engine']} functions of the other engine")
            if args.list:
                for a, fa, b, fb in w["climb_list"]:
                    print(f"  climb: {a}.{fa} -> {b}.{fb}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
