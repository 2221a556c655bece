"""The class report's input: one entry per student (or group), whatever layout or roster it came from."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from grader.report import Report

EntryStatus = Literal["graded", "missing", "submission_error"]
"""graded: a report exists; missing: on the roster with no submission; submission_error: a submission
that could not be graded at all (its report, when there is one, says why)."""


@dataclass(frozen=True)
class ClassEntry:
    """One student (or group) of the class, as the class report sees them.

    Attributes:
        identity: Who it is, as the source system names them (a Canvas user id, a GitHub user name, ...).
        name: Their name from the roster, when known.
        report: Their grade report; None when missing (or when a submission error left no report).
        late: Whether the source marked the submission late.
        status: graded, missing or submission_error (see ``EntryStatus``).
        note: What to tell the instructor (why the submission could not be graded, which file was graded).
        report_href: Link to their own report, relative to the class page; None when there is none.
    """

    identity: str
    name: str | None = None
    report: Report | None = None
    late: bool = False
    status: EntryStatus = "graded"
    note: str = ""
    report_href: str | None = None
