"""Which lab and edition a submission was written for, read statically from its source (never run) in the
parent.

The file's marks (`grader.lab.editions.marks`: its functions, imports and name, read within bounds with `ast`
only) are shown to each lab's rules (`grader.lab.labs.Lab.detect`), the later labs first, the first lab last:
the first rule set that recognises the file decides its lab and edition (`opengym_marks`, `rl2_marks` state
their rules and reasons). A file no lab recognises (empty, unreadable, none of any lab's functions or gym
imports) shows no lab and no edition: it is taken as the first lab's first edition, `classic`, and a class's
choice does not count it.

Detection chooses the lab and edition of a student's own `check`; grading for a gradebook grades what the
instructor chose, and `edition_note` tells a file written for another lab or other problems so.
"""

from __future__ import annotations

from pathlib import Path

from grader.lab.editions import DEFAULT_EDITION, EDITIONS
from grader.lab.editions.marks import Detection, Marks, read_marks, source_marks
from grader.lab.editions.pack import Edition
from grader.lab.labs import LABS, lab_of_edition
from grader.submission.notebook import MAX_NOTEBOOK_BYTES

__all__ = ["MAX_NOTEBOOK_BYTES", "Detection", "detect_edition", "detect_source", "edition_note"]


def detect_edition(path: Path, name: str | None = None) -> Detection:
    """The lab and edition of a `.py` or `.ipynb` submission, from the functions it defines, what it imports
    and its name (``name``: the file's own name where its copy on disk is numbered; else ``path.name``)."""
    return detected(read_marks(path, name))


def detect_source(source: bytes, name: str) -> Detection:
    """The lab and edition of Python source already read (a `.py` file's bytes, or the module built from a
    notebook's cells), bounded as `detect_edition` bounds a file."""
    return detected(source_marks(source, name))


def detected(marks: Marks) -> Detection:
    """What the marks show: the first lab (later labs asked first) whose rules recognise them."""
    first = EDITIONS[DEFAULT_EDITION]
    if not marks.readable:
        reason = f"{marks.name} could not be read as Python, so it shows no edition"
        return Detection(first, reason, shown=False, lab_shown=False)
    for lab in reversed(LABS.values()):
        found = lab.detect(marks)
        if found is not None:
            return found
    return Detection(
        first,
        "it shows no edition: it imports no gym and defines none of a later edition's functions or render flags, nor any lab's functions",  # noqa: E501
        shown=False,
        lab_shown=False,
    )


def edition_note(graded: Edition, found: Detection) -> str | None:
    """What a report tells a file written for another lab, or other problems, than the edition graded (None:
    it is not).

    Editions grading the same problems (the first lab's 1-3) are not told: the compatibility layer runs each
    one's API.
    """
    if not found.lab_shown:
        return None
    shown_lab, graded_lab = lab_of_edition(found.edition), lab_of_edition(graded)
    if shown_lab is not graded_lab:
        return (
            f"This file looks written for the lab {shown_lab.label}: {found.reason}. "
            f"Your assignment is the lab {graded_lab.label}, edition {graded.name} ({graded.title}), "
            "so it was graded on that lab's problems; check that you handed in the file of this assignment."
        )
    if not found.shown or found.edition.registry is graded.registry:
        return None
    return (
        f"This file looks written for edition {found.edition.number} ({found.edition.name}, "
        f"{found.edition.title}): {found.reason}. Your assignment is edition {graded.number} ({graded.name}, "
        f"{graded.title}), so it was graded on that edition's problems; check the assignment's template."
    )
