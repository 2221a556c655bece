"""Moodle "Download all submissions": ``{Full Name}_{participant id}_assignsubmission_file_/`` folders,
or flat
files with that prefix (``..._assignsubmission_file_{original}``); online text comes as ``_onlinetext_``.

The student is the participant id (names repeat; the id does not).
"""

from __future__ import annotations

import re
from collections import defaultdict

from grader.classroom.layouts.protocol import Group, Grouping, marked_share
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

MOODLE_NAME = re.compile(r"^(?P<name>.+)_(?P<id>\d+)_assignsubmission_(?P<plugin>[a-z]+)_(?P<rest>.*)$")


class MoodleLayout:
    """See the module docstring."""

    name = "moodle"
    title = "Moodle Download all submissions"

    def score(self, tree: Tree) -> float:
        """The share of top-level names carrying Moodle's ``_{id}_assignsubmission_`` mark."""
        return marked_share(tree, MOODLE_NAME.match)

    def group(self, tree: Tree) -> Grouping:
        """A group per participant id."""
        grouping = Grouping()
        files: dict[str, list[tuple[Entry, str]]] = defaultdict(list)
        names: dict[str, str] = {}
        for entry in tree.entries:
            match = MOODLE_NAME.match(entry.parts[0])
            if match is None:
                grouping.unattributed.append(
                    Skipped(entry.relative, "not under a {Full Name}_{participant id}_assignsubmission_ name")
                )
                continue
            names.setdefault(match["id"], match["name"])
            original = "/".join(part for part in (match["rest"], *entry.parts[1:]) if part)
            files[match["id"]].append((entry, original or entry.name))
        for identity, found in sorted(files.items()):
            grouping.groups.append(Group((Member(identity, names[identity]),), found))
        return grouping
