"""The lab and edition of a class graded without `--lab`, `--edition` or a configuration: those its files all
show.

What a student is graded on is the instructor's assignment, never a majority of the class's files: each
submission's graded file is read statically (`grader.lab.editions.detection`, never run). First the lab:
files that show no lab (empty, unreadable, nothing of any lab) are left out, and when the others show
different labs, `ClassEditions.disagreement` names each lab and whose files are behind it. Then the edition
within the class's lab: files that show no edition are left out, and the class is graded as the edition the
others show only when they all ask the same problems (the first lab's editions 1-3 grade the same problems
and agree); otherwise `disagreement` says which editions were found and whose files are behind each. Either
way the command stops before grading so that the instructor names the assignment's lab or edition.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from grader.lab.editions import DEFAULT_EDITION, EDITIONS
from grader.lab.editions.choice import EditionChoice, default_config
from grader.lab.editions.detection import Detection, detect_edition
from grader.lab.editions.rl1 import RL1
from grader.lab.labs import DEFAULT_LAB, LABS, default_edition_of

MAX_NAMED = 20
"""Identities named per edition in a disagreement (the rest are counted)."""


@dataclass(frozen=True)
class ClassEditions:
    """The edition a class is graded as (or why none can be chosen), and each submission's own detection.

    Attributes:
        choice: The class's edition, its configuration (None: the bundled one) and why.
        detected: Each submission's detection, by identity (in the order given).
        disagreement: Why no edition is chosen (files showing editions of different problems), with the
            editions found and whose files are behind each; None when `choice` grades the class.
    """

    choice: EditionChoice
    detected: Mapping[str, Detection]
    disagreement: str | None = None

    def lines(self) -> list[str]:
        """What `gymgrade grade` prints: the class's edition, then one line per submission."""
        lines = [self.choice.line]
        for identity, found in self.detected.items():
            shown = found.edition.name if found.shown else "no edition"
            lines.append(f"  {identity}: {shown}: {found.reason}")
        return lines


def class_editions(files: Mapping[str, Path], names: Mapping[str, str] | None = None) -> ClassEditions:
    """Detect each submission's lab and edition and choose the class's, or say why none can be chosen.

    Args:
        files: Each submission's graded file, by identity.
        names: Each file's own name, by identity, where its copy on disk is numbered (a class's zip).

    Returns:
        The class's edition: of the one lab its files show, the edition every file showing one asks the
        problems of (of several names for the same problems, the most common, a tie to the newer); when no
        file shows an edition, the lab's default (the first lab's first edition, another lab's current).
        With files showing different labs, or editions of different problems, `disagreement` is set.
    """
    detected = {
        identity: detect_edition(path, (names or {}).get(identity)) for identity, path in files.items()
    }
    labs = {found.edition.lab for found in detected.values() if found.lab_shown}
    if len(labs) > 1:
        first = EDITIONS[DEFAULT_EDITION]
        reason = f"no --lab, --edition or configuration, and the files show different labs ({', '.join(sorted(labs))})"  # noqa: E501
        return ClassEditions(EditionChoice(first, None, reason), detected, _lab_disagreement(detected))
    lab = LABS[labs.pop()] if labs else LABS[DEFAULT_LAB]
    shown = {
        identity: found
        for identity, found in detected.items()
        if found.shown and found.edition.lab == lab.name
    }
    unshown = len(detected) - len(shown)
    if not shown and lab.name == DEFAULT_LAB:
        first = EDITIONS[DEFAULT_EDITION]
        reason = (
            f"no --edition and no configuration, and none of the {len(detected)} files shows an edition: "
            f"the first edition (--edition {RL1.name} grades today's)"
        )
        return ClassEditions(EditionChoice(first, None, reason), detected)
    if not shown:
        edition = default_edition_of(lab)
        reason = (
            "no --edition and no configuration; "
            f"the files show the lab {lab.name} but none of the {len(detected)} shows one of its editions: its current edition"  # noqa: E501
        )
        return ClassEditions(EditionChoice(edition, default_config(edition), reason), detected)
    problem_sets = {id(found.edition.registry) for found in shown.values()}
    order = list(EDITIONS)
    tally = Counter(found.edition.name for found in shown.values())
    named = max(tally, key=lambda name: (tally[name], order.index(name)))
    edition = EDITIONS[named]
    counts = ", ".join(f"{name} {count}" for name, count in tally.most_common())
    left_out = f"; {unshown} showing no edition not counted" if unshown else ""
    if len(problem_sets) == 1:
        reason = (
            "no --edition and no configuration; "
            f"every file that shows an edition asks its problems ({counts} of {len(detected)}{left_out})"
        )
        return ClassEditions(EditionChoice(edition, default_config(edition), reason), detected)
    reason = f"no --edition and no configuration, and the files disagree ({counts}{left_out})"
    return ClassEditions(
        EditionChoice(edition, default_config(edition), reason), detected, _disagreement(shown, unshown)
    )


def _lab_disagreement(detected: Mapping[str, Detection]) -> str:
    """Which labs the files show, whose files are behind each, and what to do."""
    by_lab: dict[str, list[str]] = {}
    for identity, found in detected.items():
        if found.lab_shown:
            by_lab.setdefault(found.edition.lab, []).append(identity)
    unshown = len(detected) - sum(len(who) for who in by_lab.values())
    order = list(LABS)
    names = sorted(by_lab, key=order.index)
    parts = [f"{LABS[name].label}, {len(by_lab[name])}: {_listed(by_lab[name])}" for name in names]
    left_out = f" ({unshown} files showing no lab are not counted)" if unshown else ""
    choices = " or ".join(f"--lab {name}" for name in names)
    return (
        f"the class's files were written for different labs{left_out}: {'; '.join(parts)}. "
        "What a student is graded on is the assignment's lab and edition, not the files': "
        "nothing was graded; "
        f'pass the assignment\'s lab ({choices}), its edition (--edition NAME) or a configuration naming it (lab = "..."); '  # noqa: E501
        "a file written for another lab is then graded as the assignment and told so"
    )


def _listed(who: list[str]) -> str:
    return ", ".join(who[:MAX_NAMED]) + (f" and {len(who) - MAX_NAMED} more" if len(who) > MAX_NAMED else "")


def _disagreement(shown: Mapping[str, Detection], unshown: int) -> str:
    """Which editions the files show, whose files are behind each, and what to do."""
    by_edition: dict[str, list[str]] = {}
    for identity, found in shown.items():
        by_edition.setdefault(found.edition.name, []).append(identity)
    order = list(EDITIONS)
    parts = []
    for name in sorted(by_edition, key=order.index):
        who = by_edition[name]
        parts.append(f"{name} ({EDITIONS[name].title}, {len(who)}): {_listed(who)}")
    left_out = f" ({unshown} files showing no edition are not counted)" if unshown else ""
    choices = " or ".join(f"--edition {name}" for name in sorted(by_edition, key=order.index))
    return (
        f"the class's files were written for editions that ask different problems{left_out}: "
        f"{'; '.join(parts)}. What a student is graded on is the assignment's edition, not the files': "
        "nothing was graded; "
        f'pass the assignment\'s edition ({choices}) or a configuration naming it (edition = "..."); '
        "a file written for another edition is then graded as the assignment and told so"
    )
