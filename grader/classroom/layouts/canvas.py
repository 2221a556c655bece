"""Canvas "Download Submissions": flat files ``{sortable name}[_LATE]_{user_id}_{attachment_id}_{original}``.

The name part is lower-cased and stripped of punctuation by Canvas, so the student is the ``user_id``
(``anon_{id}`` under anonymous grading). A group's files carry the group's name and the submitter's id.
Canvas keeps only each student's latest submission; when a student uploaded two files of one name (Canvas
then renames one ``name-1.py``), the later upload (the larger attachment id) is kept.
"""

from __future__ import annotations

import re
from collections import defaultdict

from grader.classroom.graded_file import base_name
from grader.classroom.layouts.protocol import Group, Grouping, marked_share
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

CANVAS_NAME = re.compile(
    r"^(?:(?P<anon>anon_[A-Za-z0-9]+)|(?P<name>[^_]*))(?P<late>_LATE)?"
    r"(?:_(?P<user>\d+))?_(?P<attachment>\d+)_(?P<original>.+)$"
)
CANVAS_TEXT_ENTRY = re.compile(
    r"^(?P<name>[^_]*)(?P<late>_LATE)?_(?P<user>\d+)_(?P<original>(?:text|url|link)\.\w+)$"
)
"""A submission typed into Canvas (text entry, website URL) has no attachment id."""


def parse(name: str) -> re.Match[str] | None:
    """The parts of a Canvas download name, None when it is not one."""
    match = CANVAS_NAME.match(name)
    if match is None or not (match["anon"] or match["user"]):
        match = CANVAS_TEXT_ENTRY.match(name)
    return match


class CanvasLayout:
    """See the module docstring."""

    name = "canvas"
    title = "Canvas Download Submissions"

    def score(self, tree: Tree) -> float:
        """The share of top-level names that are Canvas download names."""
        return marked_share(tree, parse)

    def group(self, tree: Tree) -> Grouping:
        """A group per user id; of two uploads of one name, the later."""
        grouping = Grouping()
        by_user: dict[str, list[tuple[int, Entry, str]]] = defaultdict(list)
        names: dict[str, str] = {}
        late: dict[str, bool] = defaultdict(bool)
        for entry in tree.entries:
            match = parse(entry.parts[0])
            if match is None:
                grouping.unattributed.append(
                    Skipped(
                        entry.relative,
                        "not named {name}_{user id}_{attachment id}_{file} as Canvas names its files",
                    )
                )
                continue
            groups = match.groupdict()
            identity = groups.get("anon") or match["user"]
            names.setdefault(identity, match["name"] or "")
            late[identity] |= bool(match["late"])
            original = "/".join((match["original"], *entry.parts[1:]))
            by_user[identity].append((int(groups.get("attachment") or 0), entry, original))
        for identity, uploads in sorted(by_user.items()):
            latest: dict[str, tuple[int, Entry, str]] = {}
            for attachment, entry, original in uploads:
                key = base_name(original).lower()
                if key not in latest or attachment > latest[key][0]:
                    latest[key] = (attachment, entry, original)
            dropped = len(uploads) - len(latest)
            grouping.groups.append(
                Group(
                    (Member(identity, names[identity]),),
                    [
                        (entry, original)
                        for _, entry, original in sorted(latest.values(), key=lambda item: item[2])
                    ],
                    late=late[identity],
                    note=f"{dropped} earlier upload{'s' if dropped != 1 else ''} of the same name left out"
                    if dropped
                    else "",
                )
            )
        return grouping
