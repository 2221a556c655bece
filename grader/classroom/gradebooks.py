"""Gradebooks people upload: ``grades.csv`` and the import formats of Canvas, Gradescope and GitHub
Classroom, built as pure functions of the class's rows. Every cell goes through
``grader.render.neutral.safe_cell``: controls and bidi overrides inert, and a leading apostrophe where
a spreadsheet would evaluate it (``= + - @`` after any blanks, their fullwidth forms, a tab, a carriage
return)."""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from grader.classroom.errors import GradebookError
from grader.classroom.model import ClassDownload, Member, Submission
from grader.classroom.roster import Roster, RosterEntry
from grader.render.neutral import safe_cell
from grader.report import Report


@dataclass(frozen=True)
class GradeRow:
    """One student's line of every gradebook.

    Attributes:
        member: The student (their identity as the source names them).
        submission: Their submission (a group's is every member's), None when they submitted nothing.
        report: The report of its graded file, None when not graded (nothing submitted, no file chosen).
        roster: Their roster entry, None without a roster or when they are not on it.
        note: What a person should know ("no submission", "not on the roster", the grader's error).
        refused_claim: Its identity matches a roster student another submission matched first: it is in
            ``grades.csv`` with a note, never in an LMS gradebook (two rows for one student there would
            give one of them the other's score).
    """

    member: Member
    submission: Submission | None
    report: Report | None
    roster: RosterEntry | None
    note: str
    refused_claim: bool = False

    @property
    def name(self) -> str:
        """The roster's name for them, else the source's."""
        return (self.roster.name if self.roster else "") or self.member.name

    @property
    def email(self) -> str:
        """The roster's email for them, else the source's."""
        return (self.roster.email if self.roster else "") or self.member.email


def class_rows(
    download: ClassDownload, reports: Mapping[str, Report], roster: Roster | None = None
) -> list[GradeRow]:
    """A row per student: each member of each submission, and each roster student who submitted nothing.

    Args:
        download: What was found.
        reports: Reports by submission identity (finished ones; the others get no scores yet).
        roster: The class roster, if any.

    Returns:
        Rows sorted by the student's identity.
    """
    counted = _counted_submissions(download)
    students = [
        (member, submission)
        for submission in download.submissions
        for member in submission.members
        if counted[member.identity] is submission
    ]
    claims = _roster_claims(students, roster)
    rows: list[GradeRow] = []
    for member, submission in students:
        report = reports.get(submission.identity)
        entry, claimed_by, _ = claims.get(member.identity, (None, None, member.identity))
        notes = []
        if submission.graded_file is None:
            notes.append(f"nothing graded: {submission.why}")
        elif report is None:
            notes.append("not graded yet")
        elif report.submission_error or report.grader_errors:
            notes.append(report.submission_error or "; ".join(report.grader_errors))
        if claimed_by is not None and roster is not None:
            column = roster.key_column(submission.source, member.identity)
            notes.append(
                f"refused: {member.identity} matches roster student {claimed_by.name or claimed_by.identity} "
                f"({column} {claimed_by.get(column or '')}), "
                f"whom {_claimant(claims, claimed_by)} matched first; "
                "left out of every LMS gradebook: rename the folder or correct the roster"
            )
        elif roster is not None and entry is None:
            notes.append("not on the roster")
        others = [
            other.identity
            for other in download.submissions
            if other is not submission and member in other.members
        ]
        if others:
            notes.append(f"also in {', '.join(others)}: the latest submission counts")
        rows.append(
            GradeRow(
                member, submission, report, entry, "; ".join(notes), refused_claim=claimed_by is not None
            )
        )
    matched = {id(entry) for entry, claimed_by, _ in claims.values() if entry is not None}
    for entry in roster.entries if roster else []:
        if id(entry) not in matched:
            rows.append(
                GradeRow(Member(entry.identity, entry.name, entry.email), None, None, entry, "no submission")
            )
    rows.sort(key=lambda row: row.member.identity)
    return rows


Claim = tuple[RosterEntry | None, RosterEntry | None, str]
"""A student's roster match: (their entry, or None; the entry they claimed but another matched first, or
None; their identity)."""


def _roster_claims(students: Sequence[tuple[Member, Submission]], roster: Roster | None) -> dict[str, Claim]:
    """Each student's roster entry, one student per entry: an identity equal to the entry's key as written
    claims it before one equal only after `roster_key`'s normalisation; then identities in order. A second
    claim is refused (recorded as the entry claimed, none matched)."""
    if roster is None:
        return {}
    found = []
    for member, submission in students:
        entry = roster.find(member.identity, submission.source)
        column = roster.key_column(submission.source, member.identity)
        exact = entry is not None and column is not None and entry.get(column) == member.identity
        found.append((not exact, member.identity, entry))
    claims: dict[str, Claim] = {}
    holder: dict[int, str] = {}
    for _, identity, entry in sorted(found, key=lambda item: (item[0], item[1])):
        if entry is None:
            claims[identity] = (None, None, identity)
        elif id(entry) in holder:
            claims[identity] = (None, entry, identity)
        else:
            holder[id(entry)] = identity
            claims[identity] = (entry, None, identity)
    return claims


def _claimant(claims: Mapping[str, Claim], entry: RosterEntry) -> str:
    """The identity whose claim on ``entry`` was kept."""
    return next(identity for identity, (held, _, _) in claims.items() if held is entry)


def _counted_submissions(download: ClassDownload) -> dict[str, Submission]:
    """The submission that counts for each student: their only one, or of several (a student in two groups
    of a Gradescope export), the latest by submission time, else the last by identity."""
    counted: dict[str, Submission] = {}
    for submission in download.submissions:
        for member in submission.members:
            current = counted.get(member.identity)
            if current is None or _later(submission, current):
                counted[member.identity] = submission
    return counted


def _later(candidate: Submission, current: Submission) -> bool:
    if candidate.submitted_at is not None and current.submitted_at is not None:
        try:
            return candidate.submitted_at >= current.submitted_at
        except TypeError:  # one time has a zone, the other not
            return True
    return True


def _number(value: float | None) -> str:
    return "" if value is None else f"{value:g}"


def _write(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\r\n")
    writer.writerow([safe_cell(cell) for cell in header])
    writer.writerows([[safe_cell(cell) for cell in row] for row in rows])
    return stream.getvalue()


def grades_csv(rows: Sequence[GradeRow], problems: Sequence[str]) -> str:
    """``grades.csv``: identity, name, email, group, graded file and why, time, late flag, sha256, seed,
    a column per problem, total, max_score, note."""
    header = [
        "student", "name", "email", "group", "graded_file", "why", "submitted_at", "late", "sha256", "seed",
        *problems, "total", "max_score", "note",
    ]  # fmt: skip
    lines = []
    for row in rows:
        submission, report = row.submission, row.report
        scores = {result.id: result.score for result in report.problems} if report else {}
        lines.append(
            [
                row.member.identity,
                row.name,
                row.email,
                submission.identity if submission and len(submission.members) > 1 else "",
                submission.graded_file.relative if submission and submission.graded_file else "",
                submission.why if submission else "",
                submission.submitted_at.isoformat() if submission and submission.submitted_at else "",
                ""
                if submission is None or submission.late is None
                else ("late" if submission.late else "on time"),
                report.sha256 if report else "",
                report.seed if report else "",
                *(_number(scores.get(problem, 0.0)) if report else "" for problem in problems),
                _number(report.score) if report else "",
                _number(report.max_score) if report else "",
                row.note,
            ]
        )
    return _write(header, lines)


@dataclass(frozen=True)
class Assignment:
    """What a gradebook names the assignment by: its title, its LMS id, and the points it is out of."""

    title: str = "OpenGym AI lab"
    lms_id: str = ""
    points: float | None = None


def canvas_user_id(row: GradeRow) -> str:
    """The student's Canvas user id ("" when unknown): the roster's ``ID`` column, else the identity of a
    Canvas download's student. Canvas matches an imported row by it and by nothing else we can give."""
    canvas_id = row.roster.get("id") if row.roster else ""
    if not canvas_id and row.submission and row.submission.source == "canvas":
        canvas_id = row.member.identity
    return canvas_id if canvas_id.isdigit() else ""


def canvas_csv(rows: Sequence[GradeRow], assignment: Assignment) -> str:
    """Canvas's gradebook import CSV: ``Student, ID, SIS User ID, SIS Login ID, Section, {title} ({id})``, a
    ``    Points Possible`` row, then a row per student Canvas can match by ``ID`` (their Canvas user id:
    the identity of a Canvas download, or the roster's ID column).

    Raises:
        GradebookError: No assignment id (Canvas makes a new assignment of a column without one).
    """
    if not assignment.lms_id:
        raise GradebookError(
            "a Canvas gradebook needs the assignment's id (the number in its URL .../assignments/ID): "
            "pass --assignment-id ID (and --assignment-title as Canvas shows it)"
        )
    column = f"{assignment.title} ({assignment.lms_id})"
    points = assignment.points if assignment.points is not None else _max_points(rows)
    lines: list[list[object]] = [["    Points Possible", "", "", "", "", _number(points)]]
    for row in _lms_rows(rows):
        canvas_id = canvas_user_id(row)
        if not canvas_id:
            continue
        roster = row.roster
        lines.append(
            [
                row.name or row.member.identity,
                canvas_id,
                roster.get("sis user id") if roster else "",
                roster.get("sis login id") if roster else "",
                roster.get("section") if roster else "",
                _number(row.report.score) if row.report else "",
            ]
        )
    return _write(["Student", "ID", "SIS User ID", "SIS Login ID", "Section", column], lines)


def gradescope_csv(rows: Sequence[GradeRow], problems: Sequence[str]) -> str:
    """Scores in the columns of Gradescope's own score export (``Name, SID, Email, Total Score, Max Points,
    Status``, one per problem), so they import where a Gradescope export's scores do."""
    lines = []
    for row in _lms_rows(rows):
        scores = {result.id: result.score for result in row.report.problems} if row.report else {}
        lines.append(
            [
                row.name,
                row.member.identity,
                row.email,
                _number(row.report.score) if row.report else "",
                _number(row.report.max_score) if row.report else "",
                "Graded" if row.report else "Missing",
                *(_number(scores.get(problem)) if row.report else "" for problem in problems),
            ]
        )
    return _write(["Name", "SID", "Email", "Total Score", "Max Points", "Status", *problems], lines)


def github_classroom_csv(rows: Sequence[GradeRow]) -> str:
    """GitHub Classroom's grades CSV.

    Columns: ``github_username, roster_identifier, points_awarded, points_available``.
    """
    points = _max_points(rows)
    lines = [
        [
            (row.roster.get("github_username") if row.roster else "") or row.member.identity,
            row.roster.get("identifier") if row.roster else "",
            _number(row.report.score) if row.report else "",
            _number(row.report.max_score if row.report else points),
        ]
        for row in _lms_rows(rows)
    ]
    return _write(["github_username", "roster_identifier", "points_awarded", "points_available"], lines)


def _lms_rows(rows: Sequence[GradeRow]) -> list[GradeRow]:
    """The rows an LMS gradebook may hold: not those whose claim on a roster student was refused."""
    return [row for row in rows if not row.refused_claim]


def _max_points(rows: Sequence[GradeRow]) -> float | None:
    return max((row.report.max_score for row in rows if row.report), default=None)


GradebookFormat = Callable[[Sequence[GradeRow], Sequence[str], Assignment], str]
GRADEBOOKS: dict[str, tuple[str, GradebookFormat]] = {
    "canvas": ("canvas.csv", lambda rows, _problems, assignment: canvas_csv(rows, assignment)),
    "gradescope": ("gradescope.csv", lambda rows, problems, _assignment: gradescope_csv(rows, problems)),
    "github-classroom": (
        "github-classroom.csv",
        lambda rows, _problems, _assignment: github_classroom_csv(rows),
    ),
}
"""Every ``--gradebook`` format: its file name in the output directory and how it is written."""
