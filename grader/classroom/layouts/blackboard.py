"""Blackboard "Assignment File Download": ``{assignment}_{username}_attempt_{YYYY-MM-DD-HH-MM-SS}_{original}``
plus one ``{assignment}_{username}_attempt_{timestamp}.txt`` per attempt (``Name: Full Name (username)``).

The student is the username; only their latest attempt is kept.
"""

from __future__ import annotations

import os
import re
from collections import defaultdict
from datetime import datetime

from grader.classroom.layouts.protocol import Group, Grouping, marked_share
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

ATTEMPT = re.compile(
    r"^(?P<head>.+)_attempt_(?P<ts>\d{4}-\d{2}-\d{2}-\d{2}-\d{2}-\d{2})(?:_(?P<original>.+)|\.txt)$"
)
NAME_LINE = re.compile(r"^Name:\s*(?P<name>.*?)\s*\((?P<user>[^()]*)\)\s*$", re.MULTILINE)


def assignment_prefix(heads: set[str]) -> str:
    """The assignment name every ``{assignment}_{username}`` shares, with its ``_`` (the part before the last
    ``_`` when there is one head)."""
    if len(heads) == 1:
        head = next(iter(heads))
        return head[: head.rfind("_") + 1]
    common = os.path.commonprefix(sorted(heads))  # noqa: RUF071 - names, compared character by character
    return common[: common.rfind("_") + 1]


class BlackboardLayout:
    """See the module docstring."""

    name = "blackboard"
    title = "Blackboard Assignment File Download"

    def score(self, tree: Tree) -> float:
        """The share of top-level names with Blackboard's ``_attempt_{timestamp}`` mark."""
        return marked_share(tree, ATTEMPT.match)

    def group(self, tree: Tree) -> Grouping:
        """A group per username, holding the files of their latest attempt."""
        grouping = Grouping()
        matched = [(entry, ATTEMPT.match(entry.parts[0])) for entry in tree.entries]
        prefix = assignment_prefix({match["head"] for _, match in matched if match})
        attempts: dict[str, dict[str, list[tuple[Entry, str]]]] = defaultdict(lambda: defaultdict(list))
        names: dict[str, str] = {}
        for entry, match in matched:
            if match is None or not match["head"].startswith(prefix) or len(match["head"]) == len(prefix):
                grouping.unattributed.append(
                    Skipped(entry.relative, "not named {assignment}_{username}_attempt_{date}_{file}")
                )
                continue
            username = match["head"][len(prefix) :]
            if match["original"] is None:
                text = entry.path.read_bytes()[:4096].decode("utf-8", "replace")
                found = NAME_LINE.search(text)
                if found:
                    names[username] = found["name"]
            original = "/".join((match["original"] or entry.name, *entry.parts[1:]))
            attempts[username][match["ts"]].append((entry, original))
        for username, by_time in sorted(attempts.items()):
            latest = max(by_time)
            earlier = len(by_time) - 1
            grouping.groups.append(
                Group(
                    (Member(username, names.get(username, "")),),
                    by_time[latest],
                    submitted_at=datetime.strptime(latest, "%Y-%m-%d-%H-%M-%S"),
                    note=f"latest of {earlier + 1} attempts" if earlier else "",
                )
            )
        return grouping
