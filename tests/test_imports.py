"""weftsim's modules import one another without a circle (issue 25, "the house").

The graph is read from the source with :mod:`ast`: every ``import`` and ``from ... import`` of a weftsim
module, at module level, under ``if TYPE_CHECKING:`` and inside functions (an import deferred into a
function is still a dependency, only hidden from the interpreter's start-up).  A package's ``__init__``
importing its own submodules is how a package exports them; every other edge must point one way.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "weftsim"


def _house():
    """scripts/house.py, the one reader of the import graph (floors, circles, arrows back up, the walk)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("house", PACKAGE.parent / "scripts" / "house.py")
    house = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(house)
    return house


def import_graph() -> dict[str, set[str]]:
    """module -> the weftsim modules it imports anywhere in its source (itself and its own packages left out)."""
    return _house().graph()


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    return _house().circles(graph)


def test_the_cycle_finder_finds_a_circle_and_a_chain_has_none():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_the_graph_sees_deferred_and_type_checking_imports():
    """The two circles of issue 25 were one deferred import and one under TYPE_CHECKING: the reader sees both
    kinds (checked on edges that exist today), so a circle of either kind would be found."""
    graph = import_graph()
    assert "weftsim.exudyn_engine.callbacks" in graph["weftsim.exudyn_engine.selection"]  # inside a function
    assert "weftsim.post.results" in graph["weftsim.checks.design_checks"]  # under TYPE_CHECKING
    assert "weftsim.errors" in graph["weftsim.post.results"]


def test_weftsim_imports_have_no_cycle():
    """No circle at all.  The last three (issue 25) were broken so: the schema of a scene file has
    its own module (weftsim.input.schema), read by the scene reader and the joint keys alike; a result
    file is read by weftsim.post.result_file alone (weftsim.post.results only writes it) and the memory
    check the archive guard needs lives in weftsim.post.npz_guard, not in weftsim.post.output, which writes
    results; a stored wear state's definitions (weftsim.wear.state) are read by both the store
    and the resume check, so the store calls the check one way."""
    assert cycles(import_graph()) == []


def test_errors_is_the_bottom_of_the_hierarchy_and_selection_needs_no_solver():
    """``weftsim.errors`` names no weftsim module (every module raises its errors; the exit statuses live in it,
    issue 32), and the
    Exudyn path's step plan (:mod:`weftsim.exudyn_engine.selection`) is plain arithmetic, no solver."""
    graph = import_graph()
    assert graph["weftsim.errors"] == set()
    assert "weftsim.exudyn_engine.solver" not in graph["weftsim.exudyn_engine.selection"]
    assert "weftsim.checks.design_checks" not in graph["weftsim.checks.plausibility"]


FORMER_CIRCLES = [
    "weftsim.post.results", "weftsim.errors", "weftsim.exudyn_engine.selection",
    "weftsim.checks.design_checks", "weftsim.sweep.store", "weftsim.input.joint_keys",
    "weftsim.input.scene", "weftsim.post.result_file", "weftsim.post.npz_guard",
    "weftsim.post.output", "weftsim.post.plots", "weftsim.wear.resume", "weftsim.wear.store",
]


@pytest.mark.parametrize("module", FORMER_CIRCLES)
def test_a_module_of_a_former_circle_imports_first_in_a_fresh_interpreter(module):
    """Each module of the former circles imported first, in a new process, succeeds."""
    subprocess.run([sys.executable, "-c", f"import {module}"], cwd=PACKAGE.parent, check=True)


def test_the_top_level_keeps_the_interface_and_each_concept_is_a_subpackage():
    """Issue 25: the modules are grouped by concept; the top level keeps the package's interface (weftsim.api),
    the errors every module raises, the version, the engine registry (issue 32) and the entry point, so a new module goes into its concept's
    subpackage (a top-level one would also stop apply_regroup.py, the script that made this layout)."""
    assert sorted(p.stem for p in PACKAGE.glob("*.py")) == ["__init__", "__main__", "api", "engines", "errors",
                                                            "version"]
    for concept in ("input", "mechanism", "joint", "checks", "post", "cli"):
        init = PACKAGE / concept / "__init__.py"
        assert init.is_file() and ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))


def test_python_m_weftsim_and_weftsim_cli_run_the_command():
    """``python -m weftsim`` and ``python -m weftsim.cli`` (the docs and tests use it) are the ``weftsim`` command."""
    for module in ("weftsim", "weftsim.cli"):
        done = subprocess.run([sys.executable, "-m", module, "scenes"], cwd=PACKAGE.parent, capture_output=True,
                              text=True)
        assert done.returncode == 0 and "loom" in done.stdout, (module, done.stderr)


ENGINE_PACKAGES = ("weftsim.reference", "weftsim.exudyn_engine")


def test_no_module_of_one_engine_imports_the_other():
    """Issue 32: the shared model (weftsim.model) sits below both engines; neither engine imports the other."""
    graph = import_graph()
    for engine in ENGINE_PACKAGES:
        other = next(e for e in ENGINE_PACKAGES if e != engine)
        for module, targets in graph.items():
            if module == engine or module.startswith(engine + "."):
                crossing = sorted(t for t in targets if t == other or t.startswith(other + "."))
                assert not crossing, f"{module} imports {crossing}"


def test_engines_are_chosen_by_name_in_one_module():
    """Only weftsim.engines names the engines' modules (its registry); every other caller gets an engine from it
    (weftsim.engines.get) or runs one through the door (simulate): no module outside the engines imports an
    engine's solve."""
    for name in import_graph():
        if name.startswith(ENGINE_PACKAGES):
            continue
        path = PACKAGE.parent / (name.replace(".", "/") + ".py")
        if not path.is_file():
            path = PACKAGE.parent / name.replace(".", "/") / "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(ENGINE_PACKAGES):
                names = {alias.name for alias in node.names}
                assert not names & {"solve", "solve_tree", "solve_compiled", "engine", "ENGINE"}, (name, names)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and name != "weftsim.engines":
                assert not node.value.startswith(("weftsim.reference:", "weftsim.exudyn_engine:",
                                                  "weftsim.reference.engine", "weftsim.exudyn_engine.engine")), name


def test_at_most_four_imports_run_back_up_a_floor():
    """Issue 32's check: at most 4 (importer, imported) pairs run from a lower floor to a higher one
    (scripts/house.py defines the floors; 13 before issue 32); the ones left are named here, so a new one fails.
    The channel names moved below the joint (weftsim.model.channels) and the oil grades into the physics
    (weftsim.physics.oil), which took four arrows away; three are left, all of the scene reader."""
    up = _house().arrows_up()
    assert len(up) <= 4, up
    assert set(up) <= {
        ("weftsim.input.scene", "weftsim.joint.contact"),  # the scene reader validates the law's parameters
        ("weftsim.input.scene", "weftsim.mechanism.kinematics"),  # ... and that the linkage assembles
        ("weftsim.input.scene", "weftsim.joint.bearing"),  # ... and gives an oil its film temperature's viscosity
    }, up


def test_house_floors_cover_every_subpackage():
    house = _house()
    for module in import_graph():
        house.floor(module)  # raises SystemExit for a subpackage in no floor


def test_a_runs_set_up_imports_neither_scipy_optimize_nor_other_commands_packages():
    """Issue 36's first second: the set-up of ``weftsim run loom`` (and of the reference scene) — the command's
    parser, the scene, the estimate (which imports the engine), the contact law and the kernel parameters — does
    not import ``scipy.optimize`` (0.2-0.4 s of CPU; the cylindrical law's exact damping at ce = 0.9 is stored,
    weftsim.joint.exact_damping), nor the packages of other commands (optimize, sweep, wear)."""
    code = (
        "import sys\n"
        "import weftsim\n"
        "from weftsim.cli.commands import build_parser\n"
        "from weftsim.cli.grammar import scene_from_args\n"
        "from weftsim.model.dynamics import pack_parameters\n"
        "for name in ('loom', 'reference'):\n"
        "    scene = scene_from_args(build_parser('run').parse_args(['run', name]))\n"
        "    weftsim.estimate(scene, 'exudyn')\n"
        "    pack_parameters(scene)\n"
        "print(' '.join(m for m in ('scipy.optimize', 'weftsim.optimize', 'weftsim.sweep', 'weftsim.wear')\n"
        "               if m in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=PACKAGE.parent, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == []
