"""The data of a class download: who submitted what, which file is graded, what was refused and why."""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path


@dataclass(frozen=True)
class Member:
    """One student of a submission, as the source system names them.

    Attributes:
        identity: The id the source keys students on (Canvas user id, Gradescope SID, GitHub username,
            Moodle participant id, nbgrader student id, Blackboard username, or a folder name / file stem);
            always a string, leading zeros kept.
        name: The name the source gives ("" when it gives none).
        email: The email the source gives ("" when it gives none).
    """

    identity: str
    name: str = ""
    email: str = ""


@dataclass(frozen=True)
class SubmittedFile:
    """A file of a submission: where it is on disk and what it is called in the download.

    Attributes:
        path: The file on disk (inside the class folder or the scratch folder a zip was read into).
        relative: Its path in the download, ``/``-separated (a zip's entries under ``name.zip/``).
        original_name: The name the student gave it (the LMS's prefixes stripped).
    """

    path: Path
    relative: str
    original_name: str


@dataclass(frozen=True)
class Submission:
    """One student's (or one group's) submission: grouped files, the graded one and why.

    Attributes:
        identity: The key of the submission: its member's identity, or the members' joined by ``+``.
        display_name: What to call it in progress lines ("Ada Lovelace (1234)").
        members: Who it counts for (a group submission counts for every member).
        files: Every file of the submission (the graded one included).
        graded_file: The file graded, None when no file can be chosen (``why`` says why).
        why: Why that file is graded (or why none is).
        submitted_at: When it was submitted, where the source says.
        late: Whether the source marks it late (None: the source does not say).
        source: The layout's name.
        refused: Its files refused for safety (``why`` names the first few and counts the rest).
    """

    identity: str
    display_name: str
    members: tuple[Member, ...]
    files: tuple[SubmittedFile, ...]
    graded_file: SubmittedFile | None
    why: str
    submitted_at: datetime | None = None
    late: bool | None = None
    source: str = ""
    refused: tuple[Skipped, ...] = ()


@dataclass(frozen=True)
class Skipped:
    """A file or entry left out, and why (refused for safety, or not attributable to anyone)."""

    where: str
    reason: str


@dataclass
class ClassDownload:
    """What :func:`grader.classroom.discover` found in a class download.

    Attributes:
        layout: The layout's name ("canvas", "plain", ...).
        root: The folder read (the scratch copy when a zip was given).
        submissions: One per student or group, sorted by identity.
        unattributed: Files no student can be named for (listed, never guessed).
        refused: Files and entries refused for safety (links, devices, zip entries leaving the folder...).
        ignored: Files skipped silently by rule (``__MACOSX``, hidden files, checkpoints), counted only.
    """

    layout: str
    root: Path
    submissions: list[Submission] = field(default_factory=list)
    unattributed: list[Skipped] = field(default_factory=list)
    refused: list[Skipped] = field(default_factory=list)
    ignored: int = 0
