"""Words that went stale (issue 35), each now written from one source and checked against it: the docs
sections the code points to, the ensemble's help (its section, every distribution), the subcommand list,
the README's test counts, the install hint of a missing extra, the after-run check line's window."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from weftsim.cli.commands import WEAR_HELP, build_parser
from weftsim.cli.wear import ENSEMBLE_SECTION
from weftsim.wear.uncertain import SIGNATURES

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = re.compile(r"docs/([a-z0-9_-]+)\.md section (\d+)")


def _sections(page: str) -> dict[int, str]:
    """Section number -> heading of ``docs/<page>.md`` (``## 9. Ensembles: ...``)."""
    text = (ROOT / "docs" / f"{page}.md").read_text(encoding="utf-8")
    return {int(m.group(1)): m.group(2) for m in re.finditer(r"^## (\d+)\. (.*)$", text, re.M)}


def _references() -> list[tuple[str, int, str, str]]:
    """Every ``docs/PAGE.md section N`` in the package's code: (page, N, file, line)."""
    out = []
    for path in sorted((ROOT / "weftsim").rglob("*.py")):
        for line in path.read_text(encoding="utf-8").splitlines():
            for m in REFERENCE.finditer(line):
                out.append((m.group(1), int(m.group(2)), str(path.relative_to(ROOT)), line.strip()))
    return out


def test_every_section_the_code_names_exists():
    missing = [(file, f"docs/{page}.md section {n}") for page, n, file, _ in _references()
               if not (ROOT / "docs" / f"{page}.md").is_file() or n not in _sections(page)]
    assert not missing, missing


# A reference whose line names one of these topics must point to the section of that topic (by its heading).
TOPICS = {"ensemble": "Ensembles", "censored": "Ensembles", "design point": "Ensembles"}


def test_a_reference_to_a_topic_points_to_its_section():
    wrong = []
    for page, n, file, line in _references():
        if page != "wear":
            continue
        for word, heading in TOPICS.items():
            if word in line.lower() and heading not in _sections("wear")[n]:
                wrong.append((file, line))
    assert not wrong, wrong


def test_the_ensemble_help_names_its_section_and_every_distribution(capsys):
    page, number = REFERENCE.match(ENSEMBLE_SECTION).groups()
    assert _sections(page)[int(number)].startswith("Ensembles")
    with pytest.raises(SystemExit):
        build_parser().parse_args(["wear", "--help"])
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps the help
    assert ENSEMBLE_SECTION in text
    for kind, names in SIGNATURES.items():
        assert f"{kind}({','.join(names)})" in text, kind


def test_the_command_list_says_what_wear_does(capsys):
    assert "(E, F, or both)" in WEAR_HELP and "--uncertain" in WEAR_HELP
    with pytest.raises(SystemExit):
        build_parser().parse_args(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert " ".join(WEAR_HELP.split()) in text
    assert "joint E over" not in text  # the old words: wear at E only


def test_the_readme_states_no_test_count_that_goes_stale():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert not re.search(r"\b[\d,]+ of [\d,]+ (when this was written|tests)", text)
    assert not re.search(r"runs the other tests \(\d", text)


def test_a_missing_extra_in_a_checkout_says_how_to_install_it_there():
    from weftsim.errors import install_command

    assert install_command("data", ROOT) == f"pip install -e '.[data]' in {ROOT} (this source checkout)"
    assert install_command("data", ROOT / "weftsim") == "pip install 'weftsim[data]'"  # an installed package


def test_the_after_run_line_says_which_checks_cover_the_start_up():
    """Pin pressure and p x v from revolution 2 on; the law's range (Hertz, delta/c) over the whole run, said so."""
    from weftsim.checks.design_checks import summary_line

    def check(name, value, limit=None):
        return {"name": name, "stage": "after", "table": "joint_e", "value": value, "limit": limit,
                "numbers": {"from_time_s": 0.1, "mean_pa": 1e6}}

    line = summary_line([check("pin_pressure", 2e6), check("hertz_pressure", 5.2e7, 3.7e8), check("penetration", 2.8)],
                        "after")
    head, _, tail = line.partition("; the contact law's range over the whole run, the start-up impact included: ")
    assert "revolution 2 on" in head and "pin pressure" in head and "Hertz" not in head
    assert "Hertz 52 MPa" in tail and "delta/c 2.8" in tail


def test_summary_json_gives_typed_degrees_back_and_names_its_ratios():
    """30 deg comes back as 30 (not 29.999999999999996), and the penetration over the clearance is not named
    like limits.max_penetration_ratio (over the journal radius)."""
    import weftsim
    from weftsim.input.scene import to_file_keys
    from weftsim.checks.plausibility import Plausibility

    keys = to_file_keys(weftsim.load_scene("loom"))
    assert keys["mechanism.crank_inclination_deg"] == 30.0 and keys["mechanism.rocker_arm_angle_deg"] == 90.0
    names = set(Plausibility.__dataclass_fields__)
    assert "max_penetration_over_clearance" in names and "max_penetration_ratio" not in names
    assert "damping_bound_enforced" in names and "damping_is_defect" not in names


def test_every_command_a_message_names_exists():
    """`weftsim list` was named by a refusal and does not exist: every command the code names in quotes or
    backticks (`weftsim X`, ``weftsim X``, 'weftsim X') is one of the command line's."""
    from weftsim.cli.commands import COMMANDS

    named = set()
    for path in (ROOT / "weftsim").rglob("*.py"):
        named |= {(m.group(1), str(path.relative_to(ROOT))) for m in
                  re.finditer(r"[`'\"]weftsim ([a-z][a-z-]*)", path.read_text(encoding="utf-8"))}
    prose = {"writes"}  # a sentence that starts "weftsim writes ..." inside quotes, not a command
    unknown = sorted((word, file) for word, file in named if word not in COMMANDS and word not in prose)
    assert not unknown, unknown
