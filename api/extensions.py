"""An enrolment's extension of one assignment: its own due time for the assignment's late policy, granted by
the course's staff with a reason, kept with who and when (``api.courses.late_policy_of`` reads them, so every
gradebook and the score the LMS holds follow a change).

An extension is keyed by enrolment (never a display name); an enrolment has at most one per assignment, and
granting again replaces it.
"""

from __future__ import annotations

from datetime import UTC, datetime

from sqlalchemy import delete, select
from sqlalchemy.orm import Session

from api.errors import InvalidRequest, NoLatePolicy
from api.models import Assignment, Extension, Student, utcnow


def grant_extension(
    session: Session, assignment: Assignment, student: Student, *, due: datetime, reason: str, author: str
) -> Extension:
    """Give an enrolment its own due time for the assignment (committed; replaces an earlier one).

    Args:
        session: A database session.
        assignment: The assignment (it must have a late policy).
        student: An enrolment of the assignment's course.
        due: The enrolment's due time (aware).
        reason: Why (not blank).
        author: Who granted it.

    Raises:
        NoLatePolicy: The assignment has no late policy, which an extension would move.
        InvalidRequest: The reason is blank.
    """
    if assignment.late_policy is None:
        raise NoLatePolicy(
            f"assignment {assignment.slug!r} has no late policy, so an extension would change nothing; "
            "give the assignment a late policy (`late` when it is created, GYMGRADE_LATE_POLICY for the default one) first"  # noqa: E501
        )
    reason = reason.strip()
    if not reason:
        raise InvalidRequest(
            "an extension needs a reason: say why", [(["body", "reason"], "empty", "missing")]
        )
    try:
        due_utc = due.astimezone(UTC).replace(tzinfo=None)
    except OverflowError:
        message = "a date in UTC falls outside the years 1 to 9999; give a date within them"
        raise InvalidRequest(message, [(["body", "due"], message, "value_error")]) from None
    row = session.scalars(
        select(Extension).where(Extension.assignment_id == assignment.id, Extension.student_id == student.id)
    ).first()
    if row is None:
        row = Extension(assignment_id=assignment.id, student_id=student.id)
        session.add(row)
    row.due = due_utc
    row.reason = reason
    row.author = author
    row.created_at = utcnow()
    session.commit()
    return row


def revoke_extension(session: Session, assignment: Assignment, student: Student) -> None:
    """Take an enrolment's extension of the assignment back, if it has one (committed)."""
    session.execute(
        delete(Extension).where(Extension.assignment_id == assignment.id, Extension.student_id == student.id)
    )
    session.commit()


def extensions_of(session: Session, assignment: Assignment) -> list[tuple[Extension, Student]]:
    """The assignment's extensions with their enrolments, by the enrolment's name."""
    rows = session.execute(
        select(Extension, Student)
        .join(Student, Student.id == Extension.student_id)
        .where(Extension.assignment_id == assignment.id)
        .order_by(Student.name)
    ).all()
    return [(extension, student) for extension, student in rows]
