"""The edition of a class graded without `--edition` or a configuration: detected per submission.

Each submission's graded file is read statically (`grader.editions.detection`, never run). A class is graded
as one edition, so that its gradebook has one set of columns: the edition whose problems most submissions
were written for (editions grading the same problems count together; a tie goes to the newer edition). Every
submission's detected edition and its reason are said; a submission written for other problems than the
class's is named with what to do.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from grader.editions import EDITIONS
from grader.editions.choice import EditionChoice, default_config
from grader.editions.detection import Detection, detect_edition


@dataclass(frozen=True)
class ClassEditions:
    """The edition a class is graded as, and each submission's own detection.

    Attributes:
        choice: The class's edition, its configuration (None: the bundled one) and why.
        detected: Each submission's detection, by identity (in the order given).
    """

    choice: EditionChoice
    detected: Mapping[str, Detection]

    def lines(self) -> list[str]:
        """What `gymgrade grade` prints: the class's edition, then one line per submission."""
        graded = self.choice.edition
        lines = [self.choice.line]
        for identity, found in self.detected.items():
            line = f"  {identity}: {found.edition.name}: {found.reason}"
            if found.edition.registry is not graded.registry:
                line += (
                    f"; graded as {graded.name} with the class (it asks other problems): "
                    f"grade it alone with --edition {found.edition.name} if that is its assignment"
                )
            lines.append(line)
        return lines


def class_editions(files: Mapping[str, Path]) -> ClassEditions:
    """Detect each submission's edition and choose the class's.

    Args:
        files: Each submission's graded file, by identity.

    Returns:
        The class's edition (the first edition for a class with no file) and every detection.
    """
    detected = {identity: detect_edition(path) for identity, path in files.items()}
    order = list(EDITIONS.values())
    by_problems: Counter[int] = Counter()
    for found in detected.values():
        by_problems[_first_with_problems(found.edition.registry)] += 1
    if not by_problems:
        first = order[0]
        return ClassEditions(EditionChoice(first, None, "no submission to detect an edition from"), detected)
    most = max(by_problems.values())
    winner = max((index for index, count in by_problems.items() if count == most))
    registry = order[winner].registry
    names = Counter(found.edition.name for found in detected.values() if found.edition.registry is registry)
    named = max(names, key=lambda name: (names[name], order.index(EDITIONS[name])))
    edition = EDITIONS[named]
    counts = ", ".join(
        f"{name} {count}"
        for name, count in Counter(found.edition.name for found in detected.values()).most_common()
    )
    reason = (
        f"detected per submission (no --edition, no configuration): {counts} of {len(detected)}; "
        f"the class is graded as the edition most submissions were written for"
    )
    return ClassEditions(EditionChoice(edition, default_config(edition), reason), detected)


def _first_with_problems(registry: object) -> int:
    """The index of the newest edition grading the same problems as `registry` (editions sharing problems
    count together)."""
    order = list(EDITIONS.values())
    return max(index for index, edition in enumerate(order) if edition.registry is registry)
