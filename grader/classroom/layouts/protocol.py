"""The contract of a layout: recognise a download, and group its files by student."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime
from typing import Protocol

from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree


@dataclass
class Group:
    """One student's (or group's) files as a layout found them, before the graded file is chosen.

    Attributes:
        members: Who submitted (one for a student, several for a group).
        files: (entry, name the student gave it) pairs.
        submitted_at: When, if the source says.
        late: Whether the source marks it late (None: it does not say).
        note: What the layout did that the output should say ("latest of 3 attempts").
    """

    members: tuple[Member, ...]
    files: list[tuple[Entry, str]] = field(default_factory=list)
    submitted_at: datetime | None = None
    late: bool | None = None
    note: str = ""

    @property
    def identity(self) -> str:
        """The submission's key: its member's identity, or its members' joined by ``+``."""
        return "+".join(member.identity for member in self.members)


@dataclass
class Grouping:
    """What a layout made of a download: groups, and the files it can name no student for."""

    groups: list[Group] = field(default_factory=list)
    unattributed: list[Skipped] = field(default_factory=list)


class Layout(Protocol):
    """A kind of class download (one module per kind under ``grader/classroom/layouts/``)."""

    name: str
    """The ``--layout`` name."""
    title: str
    """The system's name for people ("Canvas Download Submissions")."""

    def score(self, tree: Tree) -> float:
        """How surely ``tree`` is of this layout: 0 (not at all) to 1 (its marks are everywhere)."""
        ...

    def group(self, tree: Tree) -> Grouping:
        """Group the files by student.

        Raises:
            grader.classroom.errors.LayoutMismatch: The tree lacks what this layout needs (says what).
        """
        ...


def marked_share(tree: Tree, marked: Callable[[str], object]) -> float:
    """Share of the top-level names (`top_names`) that carry a layout's mark (0 for an empty download).

    Args:
        tree: The download.
        marked: Truthy for a name carrying the mark (a compiled pattern's ``match``, say).
    """
    names = top_names(tree)
    return sum(1 for name in names if marked(name)) / len(names) if names else 0.0


def top_names(tree: Tree) -> set[str]:
    """The first path component of every file (files and folders at the top of the download)."""
    return {entry.parts[0] for entry in tree.entries}
