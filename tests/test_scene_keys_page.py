"""The site's scene-key reference (docs/scene-keys.md, written by docs/_scene_keys.py at every docs build)
lists every key of the schema with a unit that is the loader's, its default and range, and the part of the
physics it belongs to (issue 25)."""

import math
import sys
from pathlib import Path

import pytest

from weftsim.input.scene import SCHEMA

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS))
import _scene_keys  # noqa: E402


@pytest.fixture(scope="module")
def page() -> str:
    return _scene_keys.page(DOCS)


def _rows(page: str) -> dict[str, list[str]]:
    """Each table row by its dotted key: the section's table (a ``## `[table]``` heading) and the row's key."""
    rows, table = {}, None
    for line in page.splitlines():
        if line.startswith("## `["):
            table = line.removeprefix("## `[").removesuffix("]`")
        elif line.startswith("| `"):
            cells = [cell.strip() for cell in line.strip("|").split(" | ")]
            rows[f"{table}.{cells[0].strip('`')}"] = cells
    return rows


def test_every_key_has_one_row_with_its_range_and_doc(page):
    rows = _rows(page)
    assert sorted(rows) == sorted(key.path for key in SCHEMA)
    for key in SCHEMA:
        row = rows[key.path]
        assert row[3] == key.allowed().replace("|", "\\|"), key.path
        assert row[4] == key.doc.replace("|", "\\|"), key.path


def test_the_unit_shown_is_the_unit_the_loader_converts_from():
    """A unit from the key's name must carry the factor the loader multiplies by (Key.scale): a key in mm
    shown in mm is read in mm. Keys without a unit in the name are converted with factor 1."""
    for key in SCHEMA:
        if key.kind not in ("float", "floats2", "floats3", "int"):
            continue
        shown, factor = _scene_keys.unit(key.path)
        assert math.isclose(factor, key.scale, rel_tol=1e-15), (key.path, shown, factor, key.scale)


def test_units_of_a_few_keys_by_name(page):
    rows = _rows(page)
    assert rows["joint_e.clearance_mm"][1] == "mm"
    assert rows["drive.speed_rpm"][1] == "rpm"
    assert rows["inertia.rod_inertia_kg_m2"][1] == "kg m²"
    assert rows["joint_e.bearing_material.max_pv_mpa_m_s"][1] == "MPa m/s"
    assert rows["limits.max_penetration_ratio"][1] == "-"


def test_required_keys_show_both_bundled_mechanisms_and_settings_their_default(page):
    rows = _rows(page)
    assert rows["mechanism.l_oe_mm"][2] == "required: 120 / 240"  # reference, loom (models/*.toml)
    assert rows["joint_e.clearance_mm"][2] == "required: 0.25 / 0.02"
    assert rows["solver.reference.method"][2] == "auto"
    assert rows["joint_e.bearing_material.max_pressure_mpa"][2] == "not set"


def test_every_key_links_to_a_page_of_the_site(page):
    """Each key's physics section is a page of docs/ (the build checks the anchor: warnings are errors)."""
    for key in SCHEMA:
        target, title = _scene_keys.section(key.path)
        name = target.partition("#")[0]
        if name == "lubrication.md" and not (DOCS / name).exists():
            continue  # the lubrication page comes with the lubrication keys
        assert (DOCS / name).is_file(), (key.path, target)
        assert f"[{title}]({target})" in page, key.path


def test_a_key_without_a_section_is_an_error():
    with pytest.raises(KeyError, match="SECTIONS"):
        _scene_keys.section("gearbox.backlash_mm")
