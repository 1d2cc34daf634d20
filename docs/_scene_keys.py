"""The scene-key reference page (``docs/scene-keys.md``), written from :data:`weftsim.input.schema.SCHEMA`.

``docs/conf.py`` calls :func:`write_page` at every build, so the page always lists the keys the code
accepts, with their units, defaults, allowed values and the part of the physics each belongs to
(``tests/test_scene_keys_page.py`` checks that every key gets all of them).
"""

from __future__ import annotations

import math
from pathlib import Path

from weftsim.input import scene as scene_module
from weftsim.input.params import Scene

# Unit suffixes of the key names, longest first: (suffix, unit as shown, factor to SI). The factor is
# checked against each key's conversion (Key.scale), so a unit shown here is the unit the loader reads.
UNITS: tuple[tuple[str, str, float], ...] = (
    ("_j_kg_k", "J/(kg K)", 1.0),
    ("_mm2_s", "mm²/s", 1e-6),
    ("_kg_m3", "kg/m³", 1.0),
    ("_w_k", "W/K", 1.0),
    ("_mpa_m_s", "MPa m/s", 1e6),
    ("_mpa_s", "mPa s", 1e-3),
    ("_um", "µm", 1e-6),
    ("_us", "µs", 1e-6),
    ("_kg_m2", "kg m²", 1.0),
    ("_m_s2", "m/s²", 1.0),
    ("_m_s", "m/s", 1.0),
    ("_per_mille", "‰ (of the pin diameter)", 1e-3),
    ("_per_gpa", "1/GPa", 1e-9),
    ("_gpa", "GPa", 1e9),
    ("_mpa", "MPa", 1e6),
    ("_deg", "deg", math.pi / 180.0),
    ("_rpm", "rpm", 2.0 * math.pi / 60.0),
    ("_mm", "mm", 1e-3),
    ("_kg", "kg", 1.0),
    ("_s", "s", 1.0),
    ("_m", "m", 1.0),
    ("_c", "°C", 1.0),
)

# Where each key belongs in the physics: (prefix of the dotted key, page#anchor, section title); the
# first matching prefix wins, so the specific ones come first. Anchors are myst's heading slugs: a
# wrong one fails the build (warnings are errors).
SECTIONS: tuple[tuple[str, str, str], ...] = (
    ("mechanism.", "physics.md#1-the-mechanism-paper-fig-1-fig-10", "physics §1"),
    ("inertia.", "physics.md#reference-mechanism", "physics §1, §4"),
    ("joint_*.wear.", "wear.md#5-parameters-and-their-sources", "wear §5"),
    ("joint_*.lubrication.", "lubrication.md", "lubrication"),
    ("joint_*.bearing_material.yield_strength", "plausibility.md#the-checks-their-limits-and-their-sources",
     "plausibility: Hertz"),
    ("joint_*.journal_material.yield_strength", "plausibility.md#the-checks-their-limits-and-their-sources",
     "plausibility: Hertz"),
    ("joint_*.bearing_material.max_", "plausibility.md#the-checks-their-limits-and-their-sources",
     "plausibility: p, p x v"),
    ("joint_*.design_clearance", "plausibility.md#the-checks-their-limits-and-their-sources",
     "plausibility: c/d"),
    ("joint_*.journal_material.", "physics.md#3-contact-force-laws", "physics §3"),
    ("joint_*.bearing_material.", "physics.md#3-contact-force-laws", "physics §3"),
    ("joint_*.law", "physics.md#3-contact-force-laws", "physics §3"),
    ("joint_*.restitution", "physics.md#3-contact-force-laws", "physics §3"),
    ("joint_*.", "physics.md#2-clearance-joint-at-e-flores-ambrósio-formulation", "physics §2"),
    ("drive.", "physics.md#4-dynamics", "physics §4"),
    ("duty.", "wear.md#12-the-looms-duty-cycle-and-its-life", "wear §12"),
    ("solver.reference.", "reference-solver.md#3-integration", "reference solver §3"),
    ("solver.exudyn.", "clearance-joint.md#the-loom-in-exudyn-mechanism-py", "Exudyn engine"),
    ("output.", "physics.md#4-dynamics", "physics §4"),
    ("compare.", "physics.md#6-what-is-reproducible", "physics §6"),
    ("limits.max_rapier_acceleration", "plausibility.md#the-checks-their-limits-and-their-sources",
     "plausibility: rapier"),
    ("limits.max_damping_ratio", "physics.md#2-clearance-joint-at-e-flores-ambrósio-formulation",
     "physics §2"),
    ("limits.", "hard-cases.md#2-failure-detection", "hard cases §2"),
    ("rapier_tape.", "rapier-tape.md", "rapier tape"),
    ("exchange.", "rapier-tape.md#7-the-weft-exchange", "weft exchange"),
)

# One paragraph per table of the scene file, in the order of the schema.
TABLES: dict[str, str] = {
    "mechanism": "The linkage's geometry: the spherical 4R, the four-bar O-E-F-G and the gear train. "
                 "Every key is required (itself or through `extends`).",
    "inertia": "Masses and moments of inertia of members 1-8. Every key is required.",
    "joint_e": "The clearance joint E (rocker 3 - rod 4): clearance, pin size, contact law, friction. "
               "Required, except the model options marked optional.",
    "joint_e.journal_material": "The pin's material (contact stiffness; yield for the Hertz check).",
    "joint_e.bearing_material": "The bushing's material: stiffness, and what the bushing permits "
                                "(the plausibility checks).",
    "joint_e.wear": "Archard wear at E (`weftsim wear`), all optional.",
    "joint_f": "An optional clearance at F (rod 4 - sector 5), docs: [Clearance at F](clearance-f.md). "
               "Absent: the ideal joint; with a clearance > 0 it needs every key `[joint_e]` needs.",
    "joint_f.journal_material": "The pin's material at F.",
    "joint_f.bearing_material": "The bushing's material at F.",
    "joint_f.wear": "Archard wear at F (`weftsim wear`), all optional; with a clearance at F alone, F takes "
                    "the keys `[joint_e.wear]` gives that it does not give itself.",
    "drive": "The crank's constant speed and the length of a run. Required.",
    "duty": "How the loom runs (`weftsim wear`): stops for warp and weft breaks, each a simulated run-down and "
            "start-up whose wear is added per running hour, and the scheduled hours that turn running hours into "
            "calendar time. All optional.",
    "solver.reference": "The reference engine's integrator; the defaults are the fast path "
                        "([Performance](performance.md)).",
    "solver.exudyn": "The Exudyn engine's model and solver; the defaults are the fast path.",
    "output": "The output grid.",
    "compare": "Tolerances of `weftsim compare` between the engines.",
    "limits": "What ends a run as failed ([Hard cases](hard-cases.md)), and the rapier heads' limit.",
    "rapier_tape": "The flexible rapier tape and its head ([The rapier tape](rapier-tape.md)), optional: absent, "
                   "the rigid rapier of mass `inertia.rapier_mass_kg`; given (even empty), the tape with these "
                   "keys' defaults, and `inertia.rapier_mass_kg` is not used.",
    "exchange": "The weft exchange with a taker head ([The weft exchange](rapier-tape.md#7-the-weft-exchange)), "
                "optional: absent, nothing is computed; given (even empty), the taker runs with these keys' "
                "defaults.",
}


def unit(path: str) -> tuple[str, float]:
    """The unit of a key, from its name's suffix, and its factor to SI; ("", 1.0) if it has none."""
    name = path.rpartition(".")[2]
    for suffix, shown, factor in UNITS:
        if name.endswith(suffix):
            return shown, factor
    return "", 1.0


def section(path: str) -> tuple[str, str]:
    """(link target, title) of the part of the physics ``path`` belongs to."""
    for prefix, target, title in SECTIONS:
        if prefix.startswith("joint_*."):
            table, rest = path.partition(".")[::2]
            if table.startswith("joint_") and rest.startswith(prefix.partition(".")[2]):
                return target, title
        elif path.startswith(prefix):
            return target, title
    raise KeyError(f"no section of the physics for scene key {path!r}: add it to docs/_scene_keys.py SECTIONS")


def _shown(value) -> str:
    if value is None:
        return "not set"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return str(value)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def page(docs: Path) -> str:
    """The Markdown of the key reference; ``docs`` is the docs directory (links to absent pages are left out)."""
    defaults = scene_module.to_file_keys(Scene())
    loom = scene_module.to_file_keys(scene_module.load_scene("loom"))
    required = set(scene_module.REQUIRED)  # a loose joint F takes what its table does not give from E
    lines = [
        "# Scene-key reference",
        "",
        "Every key a scene file (or `--set KEY=VALUE`, or `weftsim.load_scene(..., overrides=...)`) accepts, "
        "generated from the schema the loader checks against (`weftsim.input.schema.SCHEMA`) when the site is built. "
        "Units are part of the key names; the loader converts to SI. **Required** keys are part of the "
        "machine: a scene gives them itself or through `extends`; for them the column *default* gives the "
        "values of the two bundled mechanisms, reference / loom, a starting point for your own "
        "([How-to: your own mechanism](howto-own-mechanism.md)). Other keys fall back to the default shown. "
        "The sections are the tables of a scene file: `max_pressure_mpa` under `[joint_e.bearing_material]` is "
        "written `--set joint_e.bearing_material.max_pressure_mpa=27.6` on the command line.",
        "",
    ]
    groups: dict[str, list] = {}
    for key in scene_module.SCHEMA:
        groups.setdefault(key.path.rpartition(".")[0], []).append(key)
    for table, keys in groups.items():
        lines += [f"## `[{table}]`", ""]
        if table in TABLES:
            lines += [TABLES[table], ""]
        lines += [f"| key in `[{table}]` | unit | default (reference / loom) | allowed | meaning | physics |",
                  "|---|---|---|---|---|---|"]
        for key in keys:
            shown_unit, _ = unit(key.path)
            if key.path in required:
                value = f"required: {_shown(defaults[key.path])} / {_shown(loom[key.path])}"
            else:
                value = _shown(defaults[key.path])
            target, title = section(key.path)
            page_name = target.partition("#")[0]
            physics = f"[{title}]({target})" if (docs / page_name).exists() else title
            lines.append(f"| `{key.path.rpartition('.')[2]}` | {shown_unit or '-'} | {_cell(value)} | {_cell(key.allowed())} | "
                         f"{_cell(key.doc)} | {physics} |")
        lines.append("")
    lines += ["The same keys as one table, for the command line's `--set`: the README's scene reference "
              "(`python scripts/scene_reference.py`).", ""]
    return "\n".join(lines)


def write_page(docs: Path) -> Path:
    """Write ``docs/scene-keys.md`` if its text changed (an unchanged page is not rebuilt)."""
    target = docs / "scene-keys.md"
    text = page(docs)
    if not target.exists() or target.read_text() != text:
        target.write_text(text)
    return target
