"""Plain folders: one folder per student (at any depth), or one file per student in one folder.

The student is the folder's name, or the file's stem. Folders that hold no files of their own and
several folders with code (sections, terms) are looked through, so ``class/sec1/alice/`` is alice.
"""

from __future__ import annotations

from collections import defaultdict

from grader.classroom.graded_file import is_candidate
from grader.classroom.layouts.protocol import Group, Grouping
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree


class PlainLayout:
    """See the module docstring."""

    name = "plain"
    title = "plain folders (one folder or file per student)"

    def score(self, tree: Tree) -> float:
        """Any download can be read as plain folders: the fallback, below every LMS's own marks."""
        return 0.01

    def group(self, tree: Tree) -> Grouping:
        """A group per student folder, and per code file at the top; other top-level files are listed."""
        grouping = Grouping()
        _split(tree.entries, 0, grouping, top=True)
        return grouping


def _split(entries: list[Entry], depth: int, grouping: Grouping, *, top: bool) -> None:
    own = [entry for entry in entries if len(entry.parts) == depth + 1]
    folders: dict[str, list[Entry]] = defaultdict(list)
    for entry in entries:
        if len(entry.parts) > depth + 1:
            folders[entry.parts[depth]].append(entry)
    if top:
        for entry in own:
            if is_candidate(entry.name):
                stem = entry.name.rsplit(".", 1)[0]
                grouping.groups.append(Group((Member(stem),), [(entry, entry.name)]))
            else:
                grouping.unattributed.append(
                    Skipped(entry.relative, "a file outside every student's folder that is not code")
                )
        for name, inside in sorted(folders.items()):
            _student_or_container(name, inside, depth + 1, grouping)


def _student_or_container(name: str, entries: list[Entry], depth: int, grouping: Grouping) -> None:
    own = [entry for entry in entries if len(entry.parts) == depth + 1]
    with_code = {
        entry.parts[depth] for entry in entries if len(entry.parts) > depth + 1 and is_candidate(entry.name)
    }
    if not own and len(with_code) > 1:
        subfolders: dict[str, list[Entry]] = defaultdict(list)
        for entry in entries:
            subfolders[entry.parts[depth]].append(entry)
        for sub, inside in sorted(subfolders.items()):
            _student_or_container(sub, inside, depth + 1, grouping)
        return
    files = [(entry, "/".join(entry.parts[depth:])) for entry in entries]
    identity = name[: -len(".zip")] if name.lower().endswith(".zip") else name
    grouping.groups.append(Group((Member(identity),), files))
