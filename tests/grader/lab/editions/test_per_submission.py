"""A class graded with no --edition and no configuration: graded as the edition its files all show, or
stopped with which editions were found and whose files are behind each (never a majority's choice)."""

import shutil
from pathlib import Path

import pytest

from grader.lab.editions import EDITIONS
from grader.lab.editions.per_submission import class_editions

RL1, CLASSIC, VOLUME2 = EDITIONS["rl1"], EDITIONS["classic"], EDITIONS["volume2"]
NO_EDITION = {
    "empty": b"",
    "not-python": b"def random_blackjack(n:\n",
    "one-shared-function": b"def random_blackjack(n):\n    return 0.5\n",
}
"""Files that show no edition: they must not count for (or against) any edition."""


def _files(tmp_path: Path, **sources: Path | bytes) -> dict[str, Path]:
    files = {}
    for identity, source in sources.items():
        files[identity] = tmp_path / identity / (source.name if isinstance(source, Path) else "opengym.py")
        files[identity].parent.mkdir()
        if isinstance(source, Path):
            shutil.copyfile(source, files[identity])
        else:
            files[identity].write_bytes(source)
    return files


def test_a_class_whose_files_agree_is_graded_as_their_edition(tmp_path: Path) -> None:
    files = _files(tmp_path, alice=RL1.reference, bob=RL1.template, **NO_EDITION)
    editions = class_editions(files)
    assert editions.disagreement is None
    assert editions.choice.edition is RL1 and editions.choice.config == RL1.default_config
    shown = {identity: found.edition.name for identity, found in editions.detected.items() if found.shown}
    assert shown == {"alice": "rl1", "bob": "rl1"}
    lines = editions.lines()
    assert lines[0] == (
        "Edition: rl1 (Reinforcement Learning 1: Gymnasium): no --edition and no configuration; every file "
        "that shows an edition asks its problems (rl1 2 of 5; 3 showing no edition not counted)."
    )
    assert lines[1].startswith("  alice: rl1: it defines epsilon_decay(")
    assert "  empty: no edition: opengym.py could not be read as Python, so it shows no edition" not in lines
    assert "  one-shared-function: no edition: it shows no edition: it imports no gym" in "\n".join(lines)


@pytest.mark.parametrize("unshown", list(NO_EDITION), ids=list(NO_EDITION))
def test_files_showing_no_edition_are_not_votes(tmp_path: Path, unshown: str) -> None:
    # Hostile: many files that show nothing cannot move a class of one rl1 student to the first edition.
    many = {f"{unshown}{number}": NO_EDITION[unshown] for number in range(5)}
    editions = class_editions(_files(tmp_path, alice=RL1.reference, **many))
    assert editions.disagreement is None and editions.choice.edition is RL1
    assert all(not editions.detected[identity].shown for identity in many)


def test_editions_grading_the_same_problems_agree(tmp_path: Path) -> None:
    sources = {"a": CLASSIC.reference, "b": VOLUME2.template, "c": VOLUME2.reference}
    editions = class_editions(_files(tmp_path, **sources))
    assert editions.disagreement is None and editions.choice.edition is VOLUME2
    assert editions.choice.config is None, "editions 1-3 are graded with the bundled configuration"


def test_files_of_different_problems_stop_the_class_with_whose_files_show_which(tmp_path: Path) -> None:
    # Hostile: a few files written for the first edition among an rl1 class (or the reverse) no longer
    # choose the class's edition by majority; nothing is guessed.
    sources = {"a": CLASSIC.reference, "b": VOLUME2.template, "d": RL1.reference, "e": RL1.template}
    editions = class_editions(_files(tmp_path, **sources, z=b""))
    assert editions.disagreement == (
        "the class's files were written for editions that ask different problems (1 files showing no edition "
        "are not counted): classic (OpenGym AI (classic gym), 1): a; volume2 (Volume 2: Gymnasium, 1): b; "
        "rl1 (Reinforcement Learning 1: Gymnasium, 2): d, e. What a student is graded on is the assignment's "
        "edition, not the files': nothing was graded; pass the assignment's edition (--edition classic or "
        '--edition volume2 or --edition rl1) or a configuration naming it (edition = "..."); a file written '
        "for another edition is then graded as the assignment and told so"
    )


def test_an_empty_class_or_one_showing_no_edition_is_graded_as_the_first(tmp_path: Path) -> None:
    empty = class_editions({})
    assert empty.choice.edition is CLASSIC and empty.choice.config is None and empty.disagreement is None
    assert empty.lines() == [
        "Edition: classic (OpenGym AI (classic gym)): no --edition and no configuration, and none of the 0 "
        "files shows an edition: the first edition (--edition rl1 grades today's)."
    ]
    blank = class_editions(_files(tmp_path, **NO_EDITION))
    assert blank.choice.edition is CLASSIC and blank.disagreement is None


RL2_SAMPLES = Path(__file__).resolve().parents[4] / "submissions" / "rl2"


def test_a_file_claiming_the_second_lab_in_a_first_lab_class_stops_it_naming_who_is_behind_each_lab(
    tmp_path: Path,
) -> None:
    # Hostile: one file defining the second lab's functions among a first-lab class does not change the
    # class's lab, nor is it outvoted: nothing is graded until the instructor names the lab.
    sources = {"alice": RL1.reference, "bob": CLASSIC.reference, "mallory": RL2_SAMPLES / "honest_v2024.py"}
    editions = class_editions(_files(tmp_path, **sources, z=b""))
    assert editions.disagreement == (
        "the class's files were written for different labs (1 files showing no lab are not counted): "
        "opengym (OpenGym AI / Reinforcement Learning 1), 2: alice, bob; "
        "rl2 (Policy Function Iteration / Reinforcement Learning 2), 1: mallory. "
        "What a student is graded on is the assignment's lab and edition, not the files': nothing was graded; "  # noqa: E501
        "pass the assignment's lab (--lab opengym or --lab rl2), its edition (--edition NAME) or a "
        'configuration naming it (lab = "..."); a file written for another lab is then graded as the '
        "assignment and told so"
    )
    assert editions.lines()[1:] == [
        f"  {identity}: {found.edition.name if found.shown else 'no edition'}: {found.reason}"
        for identity, found in editions.detected.items()
    ]


def test_a_class_of_the_second_lab_is_graded_as_the_edition_its_files_show(tmp_path: Path) -> None:
    sources = {"a": RL2_SAMPLES / "honest_v2024.py", "b": RL2_SAMPLES / "templates" / "v2024.py"}
    no_lab = {"empty": NO_EDITION["empty"], "not-python": NO_EDITION["not-python"]}
    editions = class_editions(_files(tmp_path, **sources, **no_lab))
    assert editions.disagreement is None and editions.choice.edition is EDITIONS["v2024"]
    assert editions.choice.config == EDITIONS["v2024"].default_config
    assert editions.choice.lab_line == "Lab: rl2 (Policy Function Iteration / Reinforcement Learning 2)."


def test_second_lab_files_showing_no_edition_are_graded_as_its_current_edition(tmp_path: Path) -> None:
    lab_only = b"def value_iteration(P, nS, nA, beta=1.0):\n    return None, 0\n"
    editions = class_editions(_files(tmp_path, a=lab_only, b=lab_only, z=b""))
    assert editions.disagreement is None and editions.choice.edition is EDITIONS["v2026"]
    assert editions.choice.reason == (
        "no --edition and no configuration; the files show the lab rl2 but none of the 3 shows one of its "
        "editions: its current edition"
    )
