"""nbgrader: ``submitted/{student_id}/{assignment_id}/{notebook}.ipynb`` with ``timestamp.txt``.

The student is the student id; ``timestamp.txt`` (``2024-03-01 14:25:16.123456 UTC``) says when.
"""

from __future__ import annotations

from collections import defaultdict
from datetime import UTC, datetime

from grader.classroom.layouts.protocol import Group, Grouping
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

SUBMITTED = "submitted"
TIMESTAMP = "timestamp.txt"


def _skip(tree: Tree) -> int | None:
    """Components before the student id: 1 under ``submitted/``, 0 when given ``submitted/`` itself."""
    if any(entry.parts[0] == SUBMITTED and len(entry.parts) >= 4 for entry in tree.entries):
        return 1
    if tree.root.name == SUBMITTED:
        return 0
    return None


def parse_timestamp(text: str) -> datetime | None:
    """nbgrader's timestamp (``%Y-%m-%d %H:%M:%S.%f %Z``, UTC when it names no zone), None if unreadable."""
    text = text.strip()
    zone = UTC if text.endswith(" UTC") or text.endswith("Z") else None
    text = text.removesuffix(" UTC").removesuffix("Z")
    try:
        moment = datetime.fromisoformat(text)
    except ValueError:
        return None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=zone or UTC)
    return moment


class NbgraderLayout:
    """See the module docstring."""

    name = "nbgrader"
    title = "nbgrader submitted/ folder"

    def score(self, tree: Tree) -> float:
        """High with a ``submitted/`` folder of student/assignment folders, higher with timestamps."""
        skip = _skip(tree)
        if skip is None:
            return 0.0
        stamped = any(entry.name == TIMESTAMP and len(entry.parts) == skip + 3 for entry in tree.entries)
        return 0.97 if stamped else 0.6

    def group(self, tree: Tree) -> Grouping:
        """A group per student id; the latest timestamp of their assignment folders."""
        skip = _skip(tree) or 0
        grouping = Grouping()
        files: dict[str, list[tuple[Entry, str]]] = defaultdict(list)
        stamps: dict[str, datetime] = {}
        for entry in tree.entries:
            if (skip and entry.parts[0] != SUBMITTED) or len(entry.parts) < skip + 2:
                grouping.unattributed.append(Skipped(entry.relative, "not inside submitted/{student id}/"))
                continue
            student = entry.parts[skip]
            if entry.name == TIMESTAMP and len(entry.parts) == skip + 3:
                moment = parse_timestamp(entry.path.read_bytes()[:200].decode("utf-8", "replace"))
                if moment is not None and (student not in stamps or moment > stamps[student]):
                    stamps[student] = moment
            files[student].append((entry, "/".join(entry.parts[skip + 1 :])))
        for student, found in sorted(files.items()):
            grouping.groups.append(Group((Member(student),), found, submitted_at=stamps.get(student)))
        return grouping
