"""POST and GET /enrolments/{enrolment}/overrides (and /students/{name}/overrides, the same by the student's
name in the course): the staff's last word on an enrolment's score, kept with who and when. A student's token
is refused."""

from __future__ import annotations

from fastapi import APIRouter
from sqlalchemy.orm import Session

from api.deps import AssignmentDep, InstructorDep, SessionDep
from api.errors import (
    CourseNotFound,
    InstructorOnly,
    InvalidRequest,
    MalformedBody,
    NotAuthenticated,
    NothingGradedYet,
    StudentNotFound,
    SubmissionNotFound,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.models import Assignment, Override, Student
from api.overrides import list_overrides, record_enrolment_override
from api.schemas import OverrideCreate, OverrideView
from api.students import find_enrolment, find_student

router = APIRouter(tags=["overrides"])


def _view(override: Override, student: Student) -> OverrideView:
    return OverrideView(
        id=override.id,
        enrolment=student.id,
        student=student.name,
        submission_id=override.submission_id,
        problem=override.problem,
        points=override.points,
        reason=override.reason,
        author=override.author,
        created_at=override.created_at,
    )


@router.post(
    "/students/{name}/overrides",
    status_code=201,
    response_model=OverrideView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        StudentNotFound,
        SubmissionNotFound,
        NothingGradedYet,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_override(
    name: str, body: OverrideCreate, session: SessionDep, assignment: AssignmentDep, instructor: InstructorDep
) -> OverrideView:
    """Override the score of the course's student called ``name`` for one problem (or their total), with a
    reason; every gradebook then shows it, the machine's verdict and the reason in the row's note."""
    student = find_student(session, assignment.course_id, name)
    return _record(session, assignment, student, body, instructor.name)


@router.get(
    "/students/{name}/overrides",
    response_model=list[OverrideView],
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, InvalidRequest
    ),
)
def get_overrides(
    name: str, session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> list[OverrideView]:
    """Every override of the course's student called ``name``, oldest first (the latest per problem and upload
    counts)."""
    student = find_student(session, assignment.course_id, name)
    return [_view(override, student) for override in list_overrides(session, assignment, student)]


def _record(
    session: Session, assignment: Assignment, student: Student, body: OverrideCreate, author: str
) -> OverrideView:
    override = record_enrolment_override(
        session,
        assignment,
        student,
        problem=body.problem,
        points=body.points,
        reason=body.reason,
        author=author,
        submission_id=body.submission_id,
    )
    return _view(override, student)


@router.post(
    "/enrolments/{enrolment}/overrides",
    status_code=201,
    response_model=OverrideView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        StudentNotFound,
        SubmissionNotFound,
        NothingGradedYet,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_enrolment_override(
    enrolment: int,
    body: OverrideCreate,
    session: SessionDep,
    assignment: AssignmentDep,
    instructor: InstructorDep,
) -> OverrideView:
    """Override an enrolment's score for one problem (or their total), with a reason; every gradebook and the
    score the LMS holds then follow it."""
    student = find_enrolment(session, assignment.course_id, enrolment)
    return _record(session, assignment, student, body, instructor.name)


@router.get(
    "/enrolments/{enrolment}/overrides",
    response_model=list[OverrideView],
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, InvalidRequest
    ),
)
def get_enrolment_overrides(
    enrolment: int, session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> list[OverrideView]:
    """Every override of an enrolment, oldest first (the latest per problem and upload counts)."""
    student = find_enrolment(session, assignment.course_id, enrolment)
    return [_view(override, student) for override in list_overrides(session, assignment, student)]
