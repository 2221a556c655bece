"""Submission times the instructor gives (``--submitted-at FILE``), where the download does not hold them.

One CSV, recognised by its header, in any of these shapes:

- ``student,submitted_at``: the gradebook's student id and an ISO 8601 time;
- a Canvas submissions CSV (as the Canvas API's submissions give them): ``user_id,submitted_at``;
- Moodle's grading worksheet: ``Identifier`` (``Participant 81000``) and ``Last modified (submission)``
  (``Monday, 2 March 2026, 11:59 PM``, in the site's zone, so read in the due time's zone).

A blank time or Moodle's ``-`` means no submission and is skipped. A time without a zone is read in the due
time's zone (``grader.classroom.late.in_zone_of``). These times take the place of the download's.
"""

from __future__ import annotations

import csv
import io
from datetime import datetime

from grader.classroom.errors import LatePolicyError
from grader.render.neutral import display_text

MAX_TIMES_BYTES = 16 * 2**20
STUDENT_COLUMNS = ("student", "user_id", "identifier", "id", "sid", "username")
TIME_COLUMNS = ("submitted_at", "last modified (submission)", "date submitted", "created_at")
MOODLE_PARTICIPANT = "participant "
NO_TIME = ("", "-")
TEXT_FORMATS = ("%A, %d %B %Y, %I:%M %p", "%A, %d %B %Y, %H:%M", "%d %B %Y, %I:%M %p", "%Y-%m-%d %H:%M")
"""Times as Moodle's worksheet writes them (English locale), besides ISO 8601."""
MAX_FAULTS_SHOWN = 20


def parse_time(text: str) -> datetime | None:
    """An ISO 8601 time (``Z`` too) or one of ``TEXT_FORMATS``; None when it is neither."""
    text = text.strip()
    try:
        return datetime.fromisoformat(text.replace("Z", "+00:00") if text.endswith("Z") else text)
    except ValueError:
        pass
    for pattern in TEXT_FORMATS:
        try:
            return datetime.strptime(text, pattern)
        except ValueError:
            continue
    return None


def parse_submitted_at(data: bytes, *, where: str) -> dict[str, datetime]:
    """The submission time of each student a times CSV names.

    Raises:
        LatePolicyError: Too large, not UTF-8 CSV, no student or time column, or a time that is not one
            (every such row listed with its line).
    """
    if len(data) > MAX_TIMES_BYTES:
        raise LatePolicyError(
            f"{where} is over {MAX_TIMES_BYTES:,} bytes: pass a CSV of student,submitted_at"
        )
    try:
        rows = list(csv.reader(io.StringIO(data.decode("utf-8-sig"), newline="")))
    except (UnicodeDecodeError, csv.Error) as error:
        raise LatePolicyError(f"{where} is not a UTF-8 CSV file ({error}): save it as CSV UTF-8") from None
    header = [cell.strip().lower() for cell in rows[0]] if rows else []
    student = next((header.index(name) for name in STUDENT_COLUMNS if name in header), None)
    time = next((header.index(name) for name in TIME_COLUMNS if name in header), None)
    if student is None or time is None:
        found = ",".join(display_text(cell, 40) for cell in (rows[0][:8] if rows else [])) or "(nothing)"
        raise LatePolicyError(
            f"{where} has no {'student' if student is None else 'time'} column: expected student,submitted_at (or a Canvas submissions CSV's user_id,submitted_at, or Moodle's grading worksheet), found {found}"  # noqa: E501
        )
    times: dict[str, datetime] = {}
    faults: list[str] = []
    for line, row in enumerate(rows[1:], start=2):
        if max(student, time) >= len(row):
            continue
        who, when = row[student].strip(), row[time].strip()
        if who.lower().startswith(MOODLE_PARTICIPANT):
            who = who[len(MOODLE_PARTICIPANT) :].strip()
        if not who or when in NO_TIME:
            continue
        moment = parse_time(when)
        if moment is None:
            faults.append(
                f"line {line}: {display_text(when, 60)!r} is not a time: write e.g. 2026-03-01T23:59:00-05:00"
            )
            continue
        times[who] = moment
    if faults:
        more = len(faults) - MAX_FAULTS_SHOWN
        listed = "\n".join(f"  {fault}" for fault in faults[:MAX_FAULTS_SHOWN])
        raise LatePolicyError(
            f"{where}: refused:\n{listed}"
            + (f"\n  ... and {more:,} more" if more > 0 else "")
            + "\nCorrect these rows and run the command again."
        )
    return times
