"""The instructor's overrides in the service: recorded with who and when, checked as ``gymgrade grade
--overrides`` checks a file's rows (``grader.classroom.overrides``), applied by the gradebook.

An override belongs to one assignment and one enrolment of its course (never a display name: the
decisions read it by the enrolment's id, ``api.courses.identity``). It is the enrolment's
(``submission_id`` None: whatever upload of the assignment the gradebook counts) or one upload's
(it counts while that upload is the one the gradebook shows). Every override is kept; for a student,
problem and upload the latest counts. What a problem is worth is read from the student's graded report.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.disclosure import Disclosure
from api.errors import InvalidRequest, NothingGradedYet, SubmissionNotFound
from api.models import Assignment, JobStatus, Override, Student, Submission
from api.schemas import OverrideShown
from api.students import find_student
from grader.classroom.errors import OverridesError
from grader.classroom.overrides import MAX_REASON_CHARS, TOTAL, Overrides, check_overrides
from grader.classroom.overrides import Override as Cell
from grader.report import withheld_ids


def _graded(
    session: Session, assignment: Assignment, student: Student, submission_id: int | None
) -> Submission:
    query = select(Submission).where(
        Submission.assignment_id == assignment.id,
        Submission.student_id == student.id,
        Submission.status == JobStatus.DONE.value,
    )
    if submission_id is not None:
        query = query.where(Submission.id == submission_id)
    found = session.scalars(query.order_by(Submission.id.desc())).first()
    if found is None:
        if submission_id is not None:
            raise SubmissionNotFound(
                f"no graded submission {submission_id} of {student.name}; list theirs with GET /submissions?student=..."  # noqa: E501
            )
        raise NothingGradedYet(
            f"{student.name} has no graded submission yet: an override needs one to know what each problem is worth; "  # noqa: E501
            "override once one is graded"
        )
    return found


def maxima_of(report: Mapping[str, Any] | None) -> dict[str, float]:
    """What each problem of a stored report is worth, by id."""
    return {
        str(problem.get("id")): float(problem.get("max_score") or 0.0)
        for problem in (report or {}).get("problems", [])
    }


def record_override(
    session: Session,
    assignment: Assignment,
    *,
    student_name: str,
    problem: str,
    points: float,
    reason: str,
    author: str,
    submission_id: int | None = None,
) -> Override:
    """Check and keep an override of the course's student called ``student_name`` (see
    :func:`record_enrolment_override`).

    Raises:
        StudentNotFound: No such student.
    """
    return record_enrolment_override(
        session,
        assignment,
        find_student(session, assignment.course_id, student_name),
        problem=problem,
        points=points,
        reason=reason,
        author=author,
        submission_id=submission_id,
    )


def record_enrolment_override(
    session: Session,
    assignment: Assignment,
    student: Student,
    *,
    problem: str,
    points: float,
    reason: str,
    author: str,
    submission_id: int | None = None,
) -> Override:
    """Check and keep an override of an enrolment (of the assignment's course).

    Raises:
        SubmissionNotFound: ``submission_id`` is not a graded upload of theirs.
        NothingGradedYet: None of their uploads of the assignment is graded yet.
        InvalidRequest: An unknown problem, points outside what it is worth, or no reason (the message says
            what was expected, as ``gymgrade grade --overrides`` does).
    """
    graded = _graded(session, assignment, student, submission_id)
    reason = reason.strip()
    if not reason:
        raise InvalidRequest(
            "an override needs a reason: say why", [(["body", "reason"], "empty", "missing")]
        )
    cell = Cell(student.name, problem, points, reason[:MAX_REASON_CHARS], 1)  # named for the messages
    try:
        check_overrides(
            [cell], students=[student.name], maxima=maxima_of(graded.report), where="the override"
        )
    except OverridesError as error:
        fault = str(error).splitlines()[1].strip().removeprefix("line 1: ")
        raise InvalidRequest(
            f"refused: {fault}",
            [(["body", "problem" if "problem" in fault else "points"], fault, "value_error")],
        ) from None
    override = Override(
        assignment_id=assignment.id,
        student_id=student.id,
        submission_id=submission_id,
        problem=problem,
        points=points,
        reason=cell.reason,
        author=author,
    )
    session.add(override)
    session.commit()
    return override


def list_overrides(session: Session, assignment: Assignment, student: Student) -> list[Override]:
    """Every override of an enrolment in the assignment, oldest first."""
    return list(
        session.scalars(
            select(Override)
            .where(Override.assignment_id == assignment.id, Override.student_id == student.id)
            .order_by(Override.id)
        )
    )


def counted_overrides(
    session: Session, assignment_id: int, chosen: Mapping[int, Any]
) -> dict[int, dict[str, Override]]:
    """The overrides of the assignment that count for each enrolment (by id), by problem: the latest of those
    made for the enrolment or for the upload the gradebook shows (``chosen``: enrolment id -> its row, with
    ``id``)."""
    counted: dict[int, dict[str, Override]] = {}
    query = select(Override).where(Override.assignment_id == assignment_id)
    if len(chosen) == 1:
        query = query.where(Override.student_id.in_(list(chosen)))
    for override in session.scalars(query.order_by(Override.id)):
        shown = chosen.get(override.student_id)
        if override.submission_id is not None and (shown is None or shown.id != override.submission_id):
            continue
        counted.setdefault(override.student_id, {})[override.problem] = override
    return counted


def overrides_shown(session: Session, submission: Submission, disclosure: Disclosure) -> list[OverrideShown]:
    """The overrides that count for ``submission`` (its student's and its own, the latest per problem), as
    ``disclosure`` allows: none of a withheld problem, and no ``total`` while any problem is withheld."""
    if submission.status != JobStatus.DONE.value:
        return []
    counted = counted_overrides(session, submission.assignment_id, {submission.student_id: submission}).get(
        submission.student_id, {}
    )
    problems = (submission.report or {}).get("problems", [])
    withheld = withheld_ids(problems, disclosure.shown)
    return [
        OverrideShown(problem=o.problem, points=o.points, reason=o.reason, created_at=o.created_at)
        for problem, o in counted.items()
        if problem not in withheld and not (problem == TOTAL and withheld)
    ]


def as_decided(name: str, overrides: Mapping[str, Override]) -> Overrides:
    """An enrolment's counted overrides as ``grader.classroom`` reads them (``name``: its identity)."""
    return Overrides(
        {name: {problem: Cell(name, problem, o.points, o.reason, o.id) for problem, o in overrides.items()}}
    )


__all__ = [
    "TOTAL",
    "as_decided",
    "counted_overrides",
    "list_overrides",
    "maxima_of",
    "overrides_shown",
    "record_enrolment_override",
    "record_override",
]
