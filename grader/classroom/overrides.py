"""The instructor's overrides: a CSV ``student,problem,points,reason`` read as bounded untrusted data.

A row sets one student's points for one problem (or their ``total``) and says why. The file is checked
whole against the class before anything is written: a row naming nobody in the class, an unknown problem,
points outside ``0..max``, a repeated cell or a row without a reason refuses the file, every fault listed
with its line. What it holds is the instructor's, but it is still text a spreadsheet made: every value is
bounded here and neutralised where it is shown (``safe_cell`` in gradebooks, ``display_identity`` in
messages, the page's escaping).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field

from grader.classroom.errors import OverridesError
from grader.render.neutral import IDENTITY_SHOWN_CHARS, MAX_LINE_CHARS, display_identity, display_text

TOTAL = "total"
"""The ``problem`` of an override of the student's whole grade (after any late penalty)."""
COLUMNS = ("student", "problem", "points", "reason")
MAX_OVERRIDES_BYTES = 2 * 2**20
MAX_OVERRIDE_ROWS = 20_000
MAX_REASON_CHARS = 1_000
MAX_FAULTS_SHOWN = 20
"""Faults an error message lists (the rest are counted)."""


@dataclass(frozen=True)
class Override:
    """One cell the instructor decided.

    Attributes:
        student: The student as the gradebook names them (``grades.csv``'s ``student`` column).
        problem: A problem id, or ``total``.
        points: The points given.
        reason: Why (shown beside the machine's verdict).
        line: The line of the file it was read from (for messages).
    """

    student: str
    problem: str
    points: float
    reason: str
    line: int = 0


@dataclass(frozen=True)
class Overrides:
    """The overrides of a class, by student then problem (``total`` included)."""

    by_student: Mapping[str, Mapping[str, Override]] = field(default_factory=dict)

    def of(self, student: str) -> Mapping[str, Override]:
        """The overrides of one student, by problem id (``total`` too); empty when none."""
        return self.by_student.get(student, {})

    def __len__(self) -> int:
        return sum(len(cells) for cells in self.by_student.values())


NO_OVERRIDES = Overrides()


def _shown(value: str) -> str:
    return repr(display_identity(value, IDENTITY_SHOWN_CHARS))


def _refuse(where: str, faults: Sequence[str], what_to_do: str) -> OverridesError:
    listed = "\n".join(f"  {fault}" for fault in faults[:MAX_FAULTS_SHOWN])
    more = len(faults) - MAX_FAULTS_SHOWN
    if more > 0:
        listed += f"\n  ... and {more:,} more"
    return OverridesError(f"{where}: refused, nothing was written:\n{listed}\n{what_to_do}")


def parse_overrides(data: bytes, *, where: str) -> list[Override]:
    """The rows of an overrides file, checked on their own (not yet against the class).

    Args:
        data: The file's bytes (UTF-8, a byte order mark allowed).
        where: The file's name, for messages.

    Raises:
        OverridesError: Too large, not UTF-8 CSV, a column missing, a point that is not a number, a row
            without a reason, the same cell twice, or a total and a problem for one student.
    """
    if len(data) > MAX_OVERRIDES_BYTES:
        raise OverridesError(
            f"{where} is {len(data):,} bytes; an overrides file is at most {MAX_OVERRIDES_BYTES:,}: "
            "pass the CSV of student,problem,points,reason rows"
        )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise OverridesError(
            f"{where} is not UTF-8 text (byte {error.start}): save it as CSV UTF-8 with the columns {','.join(COLUMNS)}"  # noqa: E501
        ) from None
    try:
        rows = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as error:
        raise OverridesError(f"{where} is not a CSV file ({error}): save it as CSV") from None
    if not rows:
        raise OverridesError(
            f"{where} is empty: expected a header {','.join(COLUMNS)} and a row per override"
        )
    header = [cell.strip().lower() for cell in rows[0]]
    missing = [column for column in COLUMNS if column not in header]
    if missing:
        found = ",".join(display_text(cell, 40) for cell in rows[0][:8])
        raise OverridesError(
            f"{where} has no column {', '.join(missing)}: expected the header {','.join(COLUMNS)}, found {found or '(nothing)'}"  # noqa: E501
        )
    if len(rows) - 1 > MAX_OVERRIDE_ROWS:
        raise OverridesError(
            f"{where} has {len(rows) - 1:,} rows; at most {MAX_OVERRIDE_ROWS:,} overrides are read: split the file or remove rows"  # noqa: E501
        )
    index = {column: header.index(column) for column in COLUMNS}
    faults: list[str] = []
    overrides: list[Override] = []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        cells = {column: (row[at] if at < len(row) else "").strip() for column, at in index.items()}
        student, problem, points_text, reason = (cells[column] for column in COLUMNS)
        if not student:
            faults.append(f"line {line}: no student")
            continue
        if not problem:
            faults.append(f"line {line}: no problem for {_shown(student)}: expected a problem id or {TOTAL}")
            continue
        points = _points(points_text)
        if points is None:
            faults.append(
                f"line {line}: points {_shown(points_text)} for {_shown(student)} is not a number: write e.g. 1 or 0.5"  # noqa: E501
            )
            continue
        if not reason:
            faults.append(f"line {line}: no reason for {_shown(problem)} of {_shown(student)}: say why")
            continue
        overrides.append(Override(student, problem, points, reason[:MAX_REASON_CHARS], line))
    faults += _conflicts(overrides)
    if faults:
        raise _refuse(where, faults, "Correct these rows and run the command again.")
    return overrides


def _points(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _conflicts(overrides: Sequence[Override]) -> list[str]:
    faults: list[str] = []
    seen: dict[tuple[str, str], Override] = {}
    totals: dict[str, Override] = {}
    cells: dict[str, Override] = {}
    for override in overrides:
        key = (override.student, override.problem)
        if key in seen:
            faults.append(
                f"line {override.line}: {_shown(override.problem)} of {_shown(override.student)} is overridden again (first on line {seen[key].line}): keep one row"  # noqa: E501
            )
            continue
        seen[key] = override
        (totals if override.problem == TOTAL else cells).setdefault(override.student, override)
    for student, total in totals.items():
        if student in cells:
            faults.append(
                f"line {max(total.line, cells[student].line)}: {_shown(student)} has a {TOTAL} override (line {total.line}) and a problem override (line {cells[student].line}): "  # noqa: E501
                f"a {TOTAL} decides the whole grade, so keep either the {TOTAL} or the problems"
            )
    return faults


def check_overrides(
    overrides: Sequence[Override],
    *,
    students: Collection[str],
    maxima: Mapping[str, float],
    where: str,
) -> Overrides:
    """The overrides of a class, each checked against it.

    Args:
        overrides: Parsed rows (`parse_overrides`).
        students: Every student of the class as the gradebook names them.
        maxima: The points each graded problem is out of, by id (the ``total``'s maximum is their sum).
        where: The file's name, for messages.

    Raises:
        OverridesError: A row names nobody in the class, an unknown problem, or points outside ``0..max``.
    """
    total_max = sum(maxima.values())
    known = set(students)
    faults: list[str] = []
    by_student: dict[str, dict[str, Override]] = {}
    for override in overrides:
        if override.student not in known:
            faults.append(
                f"line {override.line}: {_shown(override.student)} is nobody in this class: "
                "write the student as grades.csv's student column names them"
            )
            continue
        if override.problem != TOTAL and override.problem not in maxima:
            faults.append(
                f"line {override.line}: unknown problem {_shown(override.problem)}: expected one of {', '.join([*maxima, TOTAL])}"  # noqa: E501
            )
            continue
        most = total_max if override.problem == TOTAL else maxima[override.problem]
        if not 0 <= override.points <= most:
            faults.append(
                f"line {override.line}: {override.points:g} points for {override.problem} of {_shown(override.student)} is outside 0..{most:g}: "  # noqa: E501
                f"{override.problem} is worth {most:g}"
            )
            continue
        by_student.setdefault(override.student, {})[override.problem] = override
    if faults:
        raise _refuse(where, faults, "Correct these rows and run the command again.")
    return Overrides(by_student)


def note_of(override: Override, machine: float | None) -> str:
    """The words a gradebook row's note gives an override: what the machine said and why it changed."""
    said = "nothing graded" if machine is None else f"{machine:g}"
    return f"{override.problem} overridden to {override.points:g} (machine: {said}): {display_text(override.reason, MAX_LINE_CHARS)}"  # noqa: E501
