"""Courses and their assignments: the embedded default kept as the settings say, and what an assignment's
row means to the rest of the service (its late policy with the extensions of its enrolments).

The embedded default is course 1 (``default``) with assignment 1 (``default``): what `gymgrade serve`
with ``GYMGRADE_INSTRUCTOR_TOKEN`` serves, and what a database of before courses migrated into. Its lab,
edition, seed policy, seed release, due date, gradebook policy and late policy are the settings'
(``GYMGRADE_LAB``, ``GYMGRADE_EDITION``, ...): :func:`sync_default` writes them into its row at every
start, so the row is what grading, disclosure and the gradebook read for every assignment alike.
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.models import Assignment, Extension, Student
from api.settings import GradebookPolicy, SeedPolicy, Settings
from grader.classroom.late import LatePolicy, read_late_policy

DEFAULT_COURSE_ID = 1
DEFAULT_ASSIGNMENT_ID = 1
"""The embedded default's rows (made by migration 0004)."""


def default_values(settings: Settings) -> dict[str, Any]:
    """The default assignment's columns as the settings give them."""
    late = read_late_policy(settings.late_policy) if settings.late_policy is not None else None
    return {
        "lab": settings.lab,
        "edition": settings.edition,
        "seed_policy": settings.seed_policy.value,
        "seed": settings.seed,
        "release_seeds": settings.release_seeds,
        "due_date": settings.due_date.astimezone(UTC).replace(tzinfo=None) if settings.due_date else None,
        "gradebook_policy": settings.gradebook_policy.value,
        "late_policy": late.model_dump(mode="json") if late is not None else None,
    }


def sync_default(session: Session, settings: Settings) -> Assignment:
    """Bring the default assignment's row to the settings (written only where it differs: several processes
    start at once).

    Args:
        session: A database session (committed here when something changed).
        settings: The service settings.

    Returns:
        The default assignment.
    """
    assignment = session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)
    changed = False
    for column, value in default_values(settings).items():
        if getattr(assignment, column) != value:
            setattr(assignment, column, value)
            changed = True
    if changed:
        session.commit()
    return assignment


def default_assignment(session: Session) -> Assignment:
    """The embedded default assignment (course 1's assignment 1)."""
    return session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)


def seed_policy_of(assignment: Assignment) -> SeedPolicy:
    """How the assignment's grading seeds are chosen."""
    return SeedPolicy(assignment.seed_policy)


def gradebook_policy_of(assignment: Assignment) -> GradebookPolicy:
    """Which graded submission of each enrolment the assignment's gradebook (and the LMS) keeps."""
    return GradebookPolicy(assignment.gradebook_policy)


def due_date_of(assignment: Assignment) -> datetime | None:
    """The due date of the assignment's ``after_due_date`` problems (aware, UTC), None when unset."""
    return assignment.due_date.replace(tzinfo=UTC) if assignment.due_date is not None else None


def identity(student_id: int) -> str:
    """How an enrolment is named to ``grader.classroom``'s decisions (overrides, extensions): its id."""
    return str(student_id)


def late_policy_of(session: Session, assignment: Assignment) -> LatePolicy | None:
    """The assignment's late policy, its extensions keyed by enrolment (:func:`identity`), None without one.

    The extensions are the assignment's ``extensions`` rows; a default assignment's
    ``GYMGRADE_LATE_POLICY`` file may still name students (``[late.extensions]``, as before courses): each
    name is read as the course's enrolment of that name, and a row of the same enrolment wins.
    """
    if assignment.late_policy is None:
        return None
    table = dict(assignment.late_policy)
    named: dict[str, Any] = table.pop("extensions", None) or {}
    extensions: dict[str, Any] = {}
    if named:
        students = session.execute(
            select(Student.id, Student.name).where(
                Student.course_id == assignment.course_id, Student.name.in_(list(named))
            )
        ).all()
        extensions.update({identity(row.id): named[row.name] for row in students})
    for row in session.scalars(select(Extension).where(Extension.assignment_id == assignment.id)):
        extensions[identity(row.student_id)] = row.due.replace(tzinfo=UTC).isoformat()
    return LatePolicy.model_validate({**table, "extensions": extensions})
