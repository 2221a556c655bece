"""The course's labs gymgrade grades, declared once: each lab's name, titles, editions and current edition.

An edition names its lab (`grader.lab.editions.pack.Edition.lab`); a lab's editions are those of
`grader.lab.editions.EDITIONS` that name it, oldest first. A lab also reads its own mark in a submission
(`detect`: which of its editions a file's static marks show, or None when they show nothing of the lab), so
adding a lab is its edition packs, its marks' rules and one entry in `LABS`: nothing else changes.

Choosing: `--lab NAME` (`check`, `grade`, `gradescope-bundle`), `GYMGRADE_LAB` (the service) and a
configuration's top-level `lab = "NAME"` choose a lab; `--edition`/`edition` choose within it (an edition of
another lab is refused, `LabConflict`); a lab named alone grades its `current` edition. Nothing named: the
first lab, `opengym`, and its first edition, `classic`, so every configuration and report that names no lab
keeps its meaning (`grader.report.FIRST_LAB`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from grader.lab.editions import DEFAULT_EDITION, EDITIONS, Edition
from grader.lab.editions.errors import LabConflict, UnknownLab
from grader.lab.editions.marks import Detection, Marks
from grader.lab.editions.opengym_marks import opengym_edition
from grader.lab.editions.rl2_marks import CURRENT as RL2_CURRENT
from grader.lab.editions.rl2_marks import FILE_NAMES as RL2_FILE_NAMES
from grader.lab.editions.rl2_marks import rl2_edition


@dataclass(frozen=True)
class Lab:
    """One lab of the course, graded in any of its editions.

    Attributes:
        name: Its id (`--lab NAME`, `lab = "NAME"`, `GYMGRADE_LAB`, a report's `lab`).
        title: What the course called it first (`OpenGym AI`).
        course_title: What the course calls it since 2024 (`Reinforcement Learning 1`).
        current: The edition graded when only the lab is named (today's).
        detect: Which of its editions a file's marks show (None: nothing of this lab).
        file_names: The names its texts and templates give the student's file, most preferred first
            (`grader.classroom.graded_file.LAB_FILE_NAMES` prefers them when choosing a student's file).
    """

    name: str
    title: str
    course_title: str
    current: str
    detect: Callable[[Marks], Detection | None]
    file_names: tuple[str, ...]

    @property
    def editions(self) -> tuple[Edition, ...]:
        """Its editions, oldest first (the packs naming this lab)."""
        return tuple(edition for edition in EDITIONS.values() if edition.lab == self.name)

    @property
    def current_edition(self) -> Edition:
        """The pack of `current`."""
        return EDITIONS[self.current]

    @property
    def assignment_title(self) -> str:
        """What a class's gradebooks call the assignment unless told (`--assignment-title`)."""
        return f"{self.title} lab"

    @property
    def label(self) -> str:
        """How a person reads it: `rl2 (Policy Function Iteration / Reinforcement Learning 2)`."""
        return f"{self.name} ({self.title} / {self.course_title})"


OPENGYM = Lab(
    "opengym",
    "OpenGym AI",
    "Reinforcement Learning 1",
    "rl1",
    opengym_edition,
    ("opengym.py", "opengym.ipynb", "gymnasium.ipynb"),
)
RL2 = Lab(
    "rl2",
    "Policy Function Iteration",
    "Reinforcement Learning 2",
    RL2_CURRENT,
    rl2_edition,
    tuple(f"{stem}.py" for stem in RL2_FILE_NAMES),
)

LABS: dict[str, Lab] = {lab.name: lab for lab in (OPENGYM, RL2)}
"""Every lab, in the course's order."""
DEFAULT_LAB = OPENGYM.name
"""The lab of everything that names none (its first edition is `DEFAULT_EDITION`)."""


def lab_of(name: object, *, where: str = "lab") -> Lab:
    """The lab of this name.

    Raises:
        UnknownLab: No lab has this name (the message lists them; `where` says who named it).
    """
    found = LABS.get(name) if isinstance(name, str) else None
    if found is None:
        known = ", ".join(lab.label for lab in LABS.values())
        raise UnknownLab(f"{where}: unknown lab {name!r}; expected one of {known} (grader/lab/labs.py)")
    return found


def lab_of_edition(edition: Edition) -> Lab:
    """The lab an edition belongs to."""
    return lab_of(edition.lab, where=f"edition {edition.name}")


def edition_in_lab(lab: Lab, edition: Edition, *, lab_named: str, edition_named: str, remedy: str) -> Edition:
    """The edition, when it is one of the lab's.

    Args:
        lab, edition: What was named.
        lab_named, edition_named: How each was named (`--lab rl2`, `GYMGRADE_EDITION=rl1`, a file's key).
        remedy: What else the person may do (after: pick one of the lab's editions).

    Raises:
        LabConflict: The edition belongs to another lab (the message names both and what to write).
    """
    if edition.lab == lab.name:
        return edition
    other = lab_of_edition(edition)
    ours = ", ".join(found.name for found in lab.editions) or "(none installed)"
    raise LabConflict(
        f"{edition_named} is an edition of lab {other.label}, but {lab_named} names lab {lab.label}: "
        f"name one of {lab.name}'s editions ({ours}), {remedy}"
    )


def default_edition_of(lab: Lab) -> Edition:
    """What a lab is graded as when nothing names its edition and no file shows one: the first lab's first
    edition (`classic`, so configurations and reports naming nothing keep their meaning), another lab's
    current edition."""
    return EDITIONS[DEFAULT_EDITION] if lab.name == DEFAULT_LAB else lab.current_edition


def lab_label(name: str) -> str:
    """How a report names its lab to a person; a name no lab has (a newer gymgrade's) is shown as it is."""
    found = LABS.get(name)
    return name if found is None else found.label
