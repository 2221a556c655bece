"""Plain folders: one folder per student, or one file per student in one folder, maybe inside sections.

The student is the folder's name, or the file's stem. Section folders (sections, terms, a folder wrapping
the class) are decided from the download's shape as a whole, never from one student's folder: a level of
folders is taken for sections only when every folder of that level holds no file of its own and at least two
subfolders with code, and no subfolder name appears under two of them (students' own subfolders repeat:
``lab/``, ``src/``). Below the sections, every folder is a student and everything under it is theirs, so a
student's own subfolders (``mallory/alice/opengym.py``) are that student's files and claim nobody.
``--sections N`` says the number of section levels outright.
"""

from __future__ import annotations

from collections import defaultdict

from grader.classroom.graded_file import is_candidate
from grader.classroom.layouts.protocol import Group, Grouping
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

MAX_SECTIONS = 8
"""Section levels a download's shape can make (``--sections`` may say more)."""


class PlainLayout:
    """See the module docstring.

    Args:
        sections: Levels of section folders above the students' folders; None: from the download's shape.
    """

    name = "plain"
    title = "plain folders (one folder or file per student)"

    def __init__(self, sections: int | None = None) -> None:
        self.sections = sections

    def score(self, tree: Tree) -> float:
        """Any download can be read as plain folders: the fallback, below every LMS's own marks."""
        return 0.01

    def group(self, tree: Tree) -> Grouping:
        """A group per student folder (below the section levels), and per code file at the top or directly
        in a section; other files outside every student's folder are listed."""
        grouping = Grouping()
        depth = self.sections if self.sections is not None else section_levels(tree.entries)
        students: dict[tuple[str, ...], list[Entry]] = defaultdict(list)
        for entry in tree.entries:
            if len(entry.parts) > depth + 1:
                students[entry.parts[: depth + 1]].append(entry)
            elif is_candidate(entry.name):
                stem = entry.name.rsplit(".", 1)[0]
                grouping.groups.append(Group((Member(stem),), [(entry, entry.name)]))
            else:
                grouping.unattributed.append(
                    Skipped(entry.relative, "a file outside every student's folder that is not code")
                )
        for folder, entries in sorted(students.items()):
            name = folder[-1]
            identity = name[: -len(".zip")] if name.lower().endswith(".zip") else name
            files = [(entry, "/".join(entry.parts[depth + 1 :])) for entry in entries]
            grouping.groups.append(Group((Member(identity),), files))
        return grouping


def section_levels(entries: list[Entry]) -> int:
    """How many levels of folders are sections, from the shape of the whole download (see the module)."""
    depth = 0
    while depth < MAX_SECTIONS and _sections_at(entries, depth):
        depth += 1
    return depth


def _sections_at(entries: list[Entry], depth: int) -> bool:
    """Whether the folders at ``depth`` (0: the top) are all sections: none holds a file of its own, each
    holds at least two subfolders with code, and no subfolder name is under two of them."""
    own: set[tuple[str, ...]] = set()
    coded: dict[tuple[str, ...], set[str]] = defaultdict(set)
    children: dict[str, set[tuple[str, ...]]] = defaultdict(set)
    for entry in entries:
        parts = entry.parts
        if len(parts) <= depth + 1:
            continue  # a file above this level: a student of its own, or unattributed
        folder = parts[: depth + 1]
        if len(parts) == depth + 2:
            own.add(folder)
            continue
        children[parts[depth + 1]].add(folder)
        if is_candidate(entry.name):
            coded[folder].add(parts[depth + 1])
    folders = own | set(coded) | {folder for parents in children.values() for folder in parents}
    if not folders or own:
        return False
    if any(len(coded.get(folder, ())) < 2 for folder in folders):
        return False
    return all(len(parents) == 1 for parents in children.values())
