"""A class graded with no --edition and no configuration: each submission's edition detected."""

import shutil
from pathlib import Path

from grader.editions import EDITIONS
from grader.editions.per_submission import class_editions

RL1, CLASSIC, VOLUME2 = EDITIONS["rl1"], EDITIONS["classic"], EDITIONS["volume2"]


def _files(tmp_path: Path, **sources: Path) -> dict[str, Path]:
    files = {}
    for identity, source in sources.items():
        files[identity] = tmp_path / identity / source.name
        files[identity].parent.mkdir()
        shutil.copyfile(source, files[identity])
    return files


def test_the_class_is_graded_as_the_edition_most_submissions_were_written_for(tmp_path: Path) -> None:
    files = _files(tmp_path, alice=RL1.reference, bob=RL1.template, carol=CLASSIC.reference)
    editions = class_editions(files)
    assert editions.choice.edition is RL1 and editions.choice.config == RL1.default_config
    assert {identity: found.edition.name for identity, found in editions.detected.items()} == {
        "alice": "rl1", "bob": "rl1", "carol": "classic"
    }  # fmt: skip
    lines = editions.lines()
    assert lines[0].startswith(
        "Edition: rl1 (Reinforcement Learning 1: Gymnasium): detected per submission (no --edition, no "
        "configuration): rl1 2, classic 1 of 3"
    )
    assert lines[1].startswith("  alice: rl1: it defines epsilon_decay(")
    (carol,) = [line for line in lines if line.startswith("  carol:")]
    assert "graded as rl1 with the class (it asks other problems): grade it alone with --edition classic" in (
        carol
    )


def test_editions_grading_the_same_problems_count_together(tmp_path: Path) -> None:
    sources = {"a": CLASSIC.reference, "b": VOLUME2.template, "c": VOLUME2.reference}
    files = _files(tmp_path, **sources, d=RL1.reference, e=RL1.template)
    editions = class_editions(files)
    # Three submissions ask the first edition's problems (classic 1, volume2 2), two ask rl1's.
    assert editions.choice.edition is VOLUME2
    assert editions.choice.config is None, "editions 1-3 are graded with the bundled configuration"
    first_three = [line for line in editions.lines() if line.startswith(("  a:", "  b:", "  c:"))]
    assert len(first_three) == 3 and not any("graded as" in line for line in first_three)
    assert all("graded as volume2 with the class" in line for line in editions.lines()[-2:])


def test_a_tie_goes_to_the_newer_edition_and_an_empty_class_to_the_first(tmp_path: Path) -> None:
    assert class_editions(_files(tmp_path, a=CLASSIC.reference, b=RL1.reference)).choice.edition is RL1
    empty = class_editions({})
    assert empty.choice.edition is CLASSIC and empty.choice.config is None
    assert empty.lines() == [
        "Edition: classic (OpenGym AI (classic gym)): no submission to detect an edition from."
    ]
