"""PUT, DELETE /enrolments/{enrolment}/extension and GET /extensions: an enrolment's own due time for the
assignment's late policy, granted by the course's staff (an instructor or a TA) with a reason. Every gradebook
and the score the LMS holds follow a change. A student's token is refused."""

from __future__ import annotations

from fastapi import APIRouter, Response

from api.deps import AssignmentDep, InstructorDep, SessionDep
from api.errors import (
    CourseNotFound,
    InstructorOnly,
    InvalidRequest,
    MalformedBody,
    NoLatePolicy,
    NotAuthenticated,
    StudentNotFound,
    UploadTooLarge,
)
from api.extensions import extensions_of, grant_extension, revoke_extension
from api.handlers import error_responses
from api.models import Extension, Student
from api.schemas import ExtensionCreate, ExtensionView
from api.students import find_enrolment

router = APIRouter(tags=["extensions"])


def _view(extension: Extension, student: Student) -> ExtensionView:
    return ExtensionView(
        enrolment=student.id,
        student=student.name,
        due=extension.due,
        reason=extension.reason,
        author=extension.author,
        created_at=extension.created_at,
    )


@router.put(
    "/enrolments/{enrolment}/extension",
    response_model=ExtensionView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        StudentNotFound,
        NoLatePolicy,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def put_extension(
    enrolment: int,
    body: ExtensionCreate,
    session: SessionDep,
    assignment: AssignmentDep,
    instructor: InstructorDep,
) -> ExtensionView:
    """Give an enrolment its own due time for the assignment's late policy (replacing an earlier one)."""
    student = find_enrolment(session, assignment.course_id, enrolment)
    extension = grant_extension(
        session, assignment, student, due=body.due, reason=body.reason, author=instructor.name
    )
    return _view(extension, student)


@router.delete(
    "/enrolments/{enrolment}/extension",
    status_code=204,
    response_class=Response,
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, InvalidRequest
    ),
)
def delete_extension(
    enrolment: int, session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> Response:
    """Take an enrolment's extension back (the assignment's due time holds for them again); nothing to take
    back is no error."""
    revoke_extension(session, assignment, find_enrolment(session, assignment.course_id, enrolment))
    return Response(status_code=204)


@router.get(
    "/extensions",
    response_model=list[ExtensionView],
    responses=error_responses(NotAuthenticated, CourseNotFound, InstructorOnly, InvalidRequest),
)
def get_extensions(
    session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> list[ExtensionView]:
    """The assignment's extensions, by the enrolment's name."""
    return [_view(extension, student) for extension, student in extensions_of(session, assignment)]
