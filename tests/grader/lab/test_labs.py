"""The labs are declared once: each edition names its lab, each lab its current edition; a configuration, a
flag or a setting chooses a lab and an edition within it, and an edition of another lab is refused."""

from pathlib import Path

import pytest

from grader.errors import ConfigError
from grader.lab.assignment import configured_edition, load_config
from grader.lab.editions import EDITIONS
from grader.lab.editions.choice import choose_edition, service_edition
from grader.lab.editions.errors import LabConflict, UnknownLab
from grader.lab.editions.rl2_marks import FILE_NAMES, FUNCTIONS
from grader.lab.labs import DEFAULT_LAB, LABS, lab_label, lab_of

REPOSITORY = Path(__file__).resolve().parents[3]
SUBMISSIONS = REPOSITORY / "submissions"


def test_every_edition_names_a_declared_lab_and_each_lab_its_own_current_edition() -> None:
    assert {edition.lab for edition in EDITIONS.values()} == set(LABS)
    for lab in LABS.values():
        assert lab.current_edition.lab == lab.name
        assert [edition.number for edition in lab.editions] == list(range(1, len(lab.editions) + 1))
    assert [edition.name for edition in LABS["opengym"].editions] == ["classic", "gym026", "volume2", "rl1"]
    assert [edition.name for edition in LABS["rl2"].editions] == ["v2018", "v2019", "v2023", "v2024", "v2026"]
    assert (LABS["opengym"].current, LABS["rl2"].current, DEFAULT_LAB) == ("rl1", "v2026", "opengym")


def test_the_second_labs_marks_are_its_editions_functions_and_no_other_labs() -> None:
    rl2 = {f.name for edition in LABS["rl2"].editions for f in edition.functions if not f.provided}
    others = {f.name for edition in LABS["opengym"].editions for f in edition.functions}
    assert set(FUNCTIONS) == rl2
    assert not set(FUNCTIONS) & others, "a mark of the second lab must not be a first-lab function"
    assert "policy_function_iteration" in FILE_NAMES and "policy_iteration" in FILE_NAMES


def test_an_unknown_lab_says_which_labs_there_are() -> None:
    with pytest.raises(UnknownLab) as raised:
        lab_of("nonsense", where="--lab")
    assert str(raised.value) == (
        "--lab: unknown lab 'nonsense'; expected one of opengym (OpenGym AI / Reinforcement Learning 1), "
        "rl2 (Policy Function Iteration / Reinforcement Learning 2) (grader/lab/labs.py)"
    )
    assert lab_label("rl9") == "rl9", "a report from a newer gymgrade is shown as it names its lab"


@pytest.mark.parametrize(
    ("data", "edition"),
    [
        ({}, "classic"),
        ({"edition": "rl1"}, "rl1"),
        ({"lab": "rl2"}, "v2026"),
        ({"lab": "opengym"}, "rl1"),
        ({"lab": "rl2", "edition": "v2019"}, "v2019"),
        ({"edition": "v2024"}, "v2024"),
    ],
    ids=[
        "nothing-is-classic",
        "edition",
        "lab-alone-rl2",
        "lab-alone-opengym",
        "lab-and-edition",
        "edition-alone-rl2",
    ],
)
def test_what_a_configuration_grades(data: dict[str, str], edition: str) -> None:
    assert configured_edition(data, where="a.toml").name == edition


def test_a_configuration_naming_an_edition_of_another_lab_is_refused_with_what_to_write(
    tmp_path: Path,
) -> None:
    config = tmp_path / "assignment.toml"
    bundled = (REPOSITORY / "grader" / "lab" / "assignment.toml").read_text(encoding="utf-8")
    config.write_text('lab = "rl2"\nedition = "rl1"\n' + bundled, encoding="utf-8")
    with pytest.raises(LabConflict) as raised:
        load_config(config)
    assert str(raised.value) == (
        f'{config}: edition = "rl1" is an edition of lab opengym (OpenGym AI / Reinforcement Learning 1), but '  # noqa: E501
        f'{config}: lab = "rl2" names lab rl2 (Policy Function Iteration / Reinforcement Learning 2): name one '  # noqa: E501
        'of rl2\'s editions (v2018, v2019, v2023, v2024, v2026), or write lab = "opengym", or leave lab out'
    )
    config.write_text('lab = "nonsense"\n' + bundled, encoding="utf-8")
    with pytest.raises(ConfigError, match="lab: unknown lab 'nonsense'"):
        load_config(config)


def test_a_configuration_naming_its_lab_keeps_its_edition_and_lab() -> None:
    rl2 = load_config(EDITIONS["v2024"].default_config)
    assert (rl2.edition, rl2.lab) == ("v2024", "rl2")
    first = load_config(None)
    assert (first.edition, first.lab) == ("classic", "opengym"), "no lab, no edition: what it meant before"


@pytest.mark.parametrize(
    ("lab", "flag", "submission", "edition", "reason"),
    [
        ("rl2", None, None, "v2026", "--lab rl2: its current edition"),
        ("opengym", None, None, "rl1", "--lab opengym: its current edition"),
        ("rl2", "v2019", None, "v2019", "chosen with --edition within --lab rl2"),
        (
            "rl2",
            None,
            "rl2/honest_v2019.py",
            "v2019",
            "--lab rl2, detected from honest_v2019.py: its run_simulation",
        ),
        (
            "rl2",
            None,
            "classic_complete.py",
            "v2026",
            "--lab rl2: its current edition (classic_complete.py shows none of its editions' marks)",
        ),
        (
            None,
            None,
            "rl2/honest_v2024.py",
            "v2024",
            "detected from honest_v2024.py: it defines model_comparison(episodes)",
        ),
        (None, "v2023", None, "v2023", "chosen with --edition"),
    ],
    ids=[
        "lab",
        "lab-opengym",
        "lab-and-edition",
        "lab-detected",
        "lab-not-shown",
        "detected-lab",
        "edition-of-rl2",
    ],
)
def test_the_command_lines_choice(
    lab: str | None, flag: str | None, submission: str | None, edition: str, reason: str
) -> None:
    path = None if submission is None else SUBMISSIONS / submission
    choice = choose_edition(flag, None, path, lab)
    assert choice.edition.name == edition
    assert choice.config == EDITIONS[edition].default_config
    assert choice.reason.startswith(reason)
    assert choice.lab_line == f"Lab: {LABS[EDITIONS[edition].lab].label}."


def test_a_flag_edition_of_another_lab_is_refused_naming_both() -> None:
    with pytest.raises(LabConflict) as raised:
        choose_edition("rl1", None, None, "rl2")
    assert str(raised.value) == (
        "--edition rl1 is an edition of lab opengym (OpenGym AI / Reinforcement Learning 1), but --lab rl2 "
        "names lab rl2 (Policy Function Iteration / Reinforcement Learning 2): name one of rl2's editions "
        "(v2018, v2019, v2023, v2024, v2026), or drop --lab"
    )
    with pytest.raises(LabConflict, match=r"v2024\.toml \(edition v2024\) is an edition of lab rl2"):
        choose_edition(None, EDITIONS["v2024"].default_config, None, "opengym")
    with pytest.raises(UnknownLab, match="--lab: unknown lab 'nonsense'"):
        choose_edition(None, None, None, "nonsense")


@pytest.mark.parametrize(
    ("edition", "lab", "graded"),
    [(None, None, "classic"), (None, "rl2", "v2026"), ("v2019", "rl2", "v2019"), ("rl1", None, "rl1")],
    ids=["unset", "lab", "lab-and-edition", "edition"],
)
def test_the_services_choice_never_reads_an_upload(edition: str | None, lab: str | None, graded: str) -> None:
    assert service_edition(edition, lab).edition.name == graded


def test_a_classs_file_choice_prefers_every_labs_own_file_names_first_labs_first() -> None:
    from grader.classroom.graded_file import LAB_FILE_NAMES

    assert tuple(name for lab in LABS.values() for name in lab.file_names) == LAB_FILE_NAMES


def test_a_gradebook_names_the_assignment_by_its_labs_title_unless_told() -> None:
    from grader.classroom.gradebooks import Assignment

    assert LABS["opengym"].assignment_title == Assignment().title == "OpenGym AI lab", "the first's unchanged"
    assert LABS["rl2"].assignment_title == "Policy Function Iteration lab"
